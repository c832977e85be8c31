/* --mask FILE: the vertices the command may move, as a list of their indices. */
#ifndef RSMOOTH_CLI_MASK_H
#define RSMOOTH_CLI_MASK_H

#include <stddef.h>
#include <stdint.h>

/* Reads `path`: 0-based vertex indices (the order the mesh file lists its vertices), separated
 * by blanks, commas or line ends, `#` starting a comment to the end of its line; those vertices
 * move, every other keeps its position bit for bit (rsmooth_params.move_mask). Writes a new
 * array of vertex_count bytes to *mask. A token that is no index, or an index >= vertex_count,
 * is refused naming the file and line (exit status 2); returns cli_files' exit statuses. */
int cli_read_mask(const char *path, size_t vertex_count, const char *mesh_path, uint8_t **mask);

#endif
