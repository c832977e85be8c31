/* The UTF-8 byte-order mark a text file was read with, written back within its format family. */
#include "io/io_internal.h"

#include <stdio.h>

bool rs_io_keeps_bom(const rsmooth_mesh *mesh, rsmooth_format format) {
    if (!mesh->extras || !mesh->extras->utf8_bom || format == RSMOOTH_FORMAT_STL_BINARY)
        return false;
    rsmooth_format source = mesh->source_format;
    return source == format || (rs_io_is_ply(source) && rs_io_is_ply(format)) ||
           (rs_io_is_stl(source) && rs_io_is_stl(format));
}

bool rs_io_put_bom(const rsmooth_mesh *mesh, rsmooth_format format, FILE *stream) {
    return !rs_io_keeps_bom(mesh, format) ||
           fwrite(RS_IO_UTF8_BOM, 1, RS_IO_UTF8_BOM_SIZE, stream) == RS_IO_UTF8_BOM_SIZE;
}
