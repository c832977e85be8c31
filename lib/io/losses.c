/* The list of what a conversion drops, as each format's loss report writes into it. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_internal.h"

#include <stdio.h>
#include <string.h>

size_t rs_io_loss_add(char *list, size_t size, const char *what) {
    size_t used = strnlen(list, size);
    if (used + 1 < size)
        snprintf(list + used, size - used, "%s%s", used ? ", " : "", what);
    return 1;
}
