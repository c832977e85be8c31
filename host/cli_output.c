/* The rsmooth command's output files (see cli_output.h): the library's one way of putting an
 * output in place (lib/io/output_file.c), with the command's messages and exit statuses. */
#define _POSIX_C_SOURCE 200809L
#include "cli_output.h"
#include "cli_files.h"
#include "io/output_file.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* How the command asks for replacing, in the refusals. */
#define REPLACE_HINT "use --force"

int cli_check_output_path(const char *path, bool replace) {
    rs_output o;
    rsmooth_error err;
    if (rs_output_resolve(&o, path, replace, REPLACE_HINT, "rsmooth", &err) == RSMOOTH_OK)
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
    rs_output o;
    rsmooth_error err;
    if (rs_output_resolve(&o, path, replace, REPLACE_HINT, "rsmooth", &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth: %s\n", err.message);
        return EXIT_USAGE;
    }
    if (rs_output_create(&o, "rsmooth", &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth: %s\n", err.message);
        rs_output_discard(&o);
        return EXIT_OTHER;
    }
    if (o.notes[0] && !quiet)
        fprintf(stderr, "rsmooth: %s: warning: %s\n", path, o.notes);
    /* the writer gets a stream of its own over a copy of the descriptor, closed (and so flushed
     * and checked) before the content is put in place */
    char message[256] = "";
    int copy = dup(o.fd);
    FILE *f = copy >= 0 ? fdopen(copy, "wb") : NULL;
    bool ok = f != NULL;
    if (!ok) {
        snprintf(message, sizeof message, "%s", strerror(errno));
        if (copy >= 0)
            close(copy);
    }
    if (ok)
        ok = write(f, user, message, sizeof message) == 0;
    if (f && fclose(f) != 0 && ok) {
        snprintf(message, sizeof message, "%s", strerror(errno));
        ok = false;
    }
    if (!ok) {
        fprintf(stderr, "rsmooth: %s: cannot write: %s\n", path, message);
        rs_output_discard(&o);
        return EXIT_OTHER;
    }
    if (rs_output_publish(&o, replace, "rsmooth", &err) != RSMOOTH_OK) {
        fprintf(stderr, "rsmooth: %s\n", err.message);
        return strstr(err.message, "already exists") ? EXIT_USAGE : EXIT_OTHER;
    }
    return EXIT_OK;
}
