/* PNG output through libpng (see png_write.h). */
#include "png_write.h"

#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <string.h>

typedef struct png_failure {
    char *message;
    size_t message_size;
} png_failure;

/* libpng calls this on a fatal error; it must not return, so it jumps back to png_write_rgb. */
static void on_error(png_structp png, png_const_charp text) {
    png_failure *failure = png_get_error_ptr(png);
    if (failure && failure->message_size)
        snprintf(failure->message, failure->message_size, "%s", text);
    png_longjmp(png, 1);
}

/* Warnings (such as a benign chunk note) do not affect the image; stay quiet as a library should.
 */
static void on_warning(png_structp png, png_const_charp text) {
    (void)png;
    (void)text;
}

int png_write_rgb(FILE *file, const uint8_t *rgb, int width, int height, char *message,
                  size_t message_size) {
    png_failure failure = {message, message_size};
    if (message_size)
        message[0] = '\0';
    if (!file || !rgb || width <= 0 || height <= 0) {
        if (message_size)
            snprintf(message, message_size, "invalid image");
        return -1;
    }
    png_structp png =
        png_create_write_struct(PNG_LIBPNG_VER_STRING, &failure, on_error, on_warning);
    if (!png) {
        if (message_size)
            snprintf(message, message_size, "out of memory");
        return -1;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        if (message_size)
            snprintf(message, message_size, "out of memory");
        return -1;
    }
    /* Nothing below changes a local after setjmp, so no local is left indeterminate by longjmp. */
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return -1;
    }
    png_init_io(png, file);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < height; y++)
        png_write_row(png, rgb + 3 * (size_t)y * (size_t)width);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    if (fflush(file) != 0 || ferror(file)) {
        if (message_size)
            snprintf(message, message_size, "write error");
        return -1;
    }
    return 0;
}
