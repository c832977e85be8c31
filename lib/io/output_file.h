/* Putting an output file in place: the one way the command, the streaming path and the MPI ranks
 * write their results (not installed). The new content goes into a temporary file beside the
 * file to write and replaces it, or takes its name, only when complete, so nobody ever sees half a
 * file. Without `replace` nothing is ever replaced, not even a file another program created while
 * this one was working: the last step fails instead. With it, a regular file, or the regular file
 * a symbolic link leads to (written through: the link stays), is replaced atomically and the new
 * file keeps its permission bits, owner and group; nothing else (folders, devices, FIFOs, links
 * to nothing) is ever replaced. Named temporaries are removed if a termination signal ends the
 * process (temporary_guard.h). */
#ifndef RSMOOTH_OUTPUT_FILE_H
#define RSMOOTH_OUTPUT_FILE_H

#include "core/rsmooth_internal.h"

#include <stdbool.h>
#include <sys/stat.h>

#define RS_OUTPUT_PATH_MAX 4096

typedef struct rs_output {
    const char *path;                /* as the caller named it, for messages */
    const char *hint;                /* how the caller asks for replacing ("use --force") */
    char target[RS_OUTPUT_PATH_MAX]; /* the file written: `path`, or the final target of a link */
    bool exists, link;               /* the target exists (`st` then holds its status); `path`
                                      * is a symbolic link */
    struct stat st;
    int fd;        /* the new content; -1 when none */
    char proc[32]; /* "/proc/self/fd/N" of an unnamed file (O_TMPFILE), or "" */
    char temporary[RS_OUTPUT_PATH_MAX + 48]; /* the named temporary (or partial), or "" */
    bool own_temporary; /* this process made it, and removes it when abandoned */
    int guard;          /* its slot in the signal guard, or -1 */
    char notes[400];    /* what the user should be told: hard links, an owner that
                         * could not be kept ("" when nothing) */
} rs_output;

/* Checks that `path` may be written, and finds what it leads to. `hint` completes the refusals
 * ("already exists (use --force to replace it)"). Fails with RSMOOTH_ERROR_IO and a message that
 * starts with the path: a name that exists without `replace`; a folder, device, FIFO or socket;
 * a link to nothing, or that cannot be followed; a folder that is missing or not writable; a path
 * too long. With `replace`, a file with other hard links gets a note. */
rsmooth_status rs_output_resolve(rs_output *o, const char *path, bool replace, const char *hint,
                                 const char *where, rsmooth_error *error);

/* Opens the new content (o->fd, read-write) beside the target: unnamed where the system allows
 * (nothing to leave behind), else a named ".rsmooth-XXXXXX" under the signal guard. A file that
 * will replace another gets its permission bits, owner and group now (a note says when the owner
 * or group cannot be kept). RSMOOTH_NAMED_TEMPORARY=1 skips the unnamed kind (tests). */
rsmooth_status rs_output_create(rs_output *o, const char *where, rsmooth_error *error);

/* The content of several processes (MPI ranks): a named partial file beside the target whose
 * name depends only on the target's path, made by one process (`make`, exclusively: another run
 * writing the same output fails here) and opened by the others. */
rsmooth_status rs_output_create_partial(rs_output *o, bool make, const char *where,
                                        rsmooth_error *error);

/* Puts the complete content in place (on disk first when it replaces a file) and closes it.
 * Without `replace`, a file that appeared at the name meanwhile fails with a message saying so.
 * The temporary is gone afterwards whatever happened. */
rsmooth_status rs_output_publish(rs_output *o, bool replace, const char *where,
                                 rsmooth_error *error);

/* Abandons the content: closes it, and removes a named temporary this process made. Safe to call
 * after rs_output_publish, and more than once. */
void rs_output_discard(rs_output *o);

#endif
