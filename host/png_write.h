/* Writing an RGB image as PNG through libpng. */
#ifndef RSMOOTH_PNG_WRITE_H
#define RSMOOTH_PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Writes `rgb` (3 * width * height bytes, rows top to bottom) to `file` as an 8-bit RGB PNG with no
 * time stamp, so the same image gives the same bytes. Returns 0, or -1 with the reason in
 * `message` (message_size bytes, always terminated). The caller opens and closes `file`. */
int png_write_rgb(FILE *file, const uint8_t *rgb, int width, int height, char *message,
                  size_t message_size);

#endif
