/* The rsmooth command's output files (see cli_output.h): the library's one way of putting an
 * output in place (rsmooth_file_write), with the command's messages and exit statuses. */
#define _POSIX_C_SOURCE 200809L
#include "cli_output.h"
#include "cli_files.h"
#include "rsmooth_io.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* How the command asks for replacing, in the refusals. */
#define REPLACE_HINT "use --force"

int cli_check_output_path(const char *path, bool replace) {
    rsmooth_error err;
    rsmooth_error_init(&err);
    if (rsmooth_file_write(path, replace, REPLACE_HINT, NULL, NULL, &err) == RSMOOTH_OK)
        return -1;
    fprintf(stderr, "rsmooth: %s\n", err.message);
    return EXIT_USAGE;
}

int cli_make_folders(const char *path, bool whole, bool quiet) {
    char folder[4096];
    const char *slash = strrchr(path, '/');
    size_t length = whole ? strlen(path) : slash ? (size_t)(slash - path) : 0;
    if (length == 0 || length >= sizeof folder)
        return -1; /* the current folder, or a name too long for the writer to refuse */
    memcpy(folder, path, length);
    folder[length] = '\0';
    struct stat st;
    if (stat(folder, &st) == 0 && S_ISDIR(st.st_mode))
        return -1;
    /* each prefix ending before a '/' (and the whole), from the top: made where missing */
    bool created = false;
    for (size_t end = 1; end <= length; end++) {
        if (end < length && folder[end] != '/')
            continue;
        char c = folder[end];
        folder[end] = '\0';
        bool made = false;
        int failure = 0;
        if (stat(folder, &st) != 0) {
            if (errno != ENOENT)
                failure = errno;
            else if (mkdir(folder, 0777) == 0)
                made = true;
            else if (errno != EEXIST || stat(folder, &st) != 0) /* EEXIST: another run's */
                failure = errno;
        }
        if (!failure && !made && !S_ISDIR(st.st_mode)) {
            fprintf(stderr, "rsmooth: %s: '%s' is not a folder\n", path, folder);
            return EXIT_USAGE;
        }
        if (failure) {
            fprintf(stderr, "rsmooth: %s: cannot make the folder '%s': %s\n", path, folder,
                    strerror(failure));
            return EXIT_USAGE;
        }
        created = created || made;
        folder[end] = c;
    }
    if (created && !quiet)
        fprintf(stderr, "rsmooth: created the folder %s\n", folder);
    return -1;
}

bool cli_same_file(const char *a, const char *b) {
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

int cli_write_atomically(const char *path, bool replace, bool quiet, cli_writer write, void *user) {
    int code = cli_check_output_path(path, replace); /* a refused path is the user's: 2 */
    if (code >= 0)
        return code;
    rsmooth_error err;
    rsmooth_error_init(&err);
    if (rsmooth_file_write(path, replace, REPLACE_HINT, write, user, &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth: %s\n", err.message);
        /* another run took the name meanwhile: as if it had been there */
        return strstr(err.message, "already exists") ? EXIT_USAGE : EXIT_OTHER;
    }
    if (err.message[0] && !quiet)
        fprintf(stderr, "rsmooth: %s: warning: %s\n", path, err.message);
    return EXIT_OK;
}
