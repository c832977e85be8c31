/* Putting an output file in place (see output_file.h). */
#define _GNU_SOURCE /* O_TMPFILE, linkat, renameat2 and RENAME_NOREPLACE (Linux) */
#include "io/output_file.h"
#include "core/environment.h"
#include "io/temporary_guard.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* The temporary's name: short, so an output name of 255 bytes (the usual limit) still has one. */
#define TEMPORARY_NAME "/.rsmooth-XXXXXX"
#define PARTIAL_NAME "/.rsmooth-partial-0123456789abcdef"

/* The folder part of `path`: "." for a bare name, "/" for a file at the root. */
static void folder_of(const char *path, char *dir, size_t size) {
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, size, ".");
    else if (slash == path)
        snprintf(dir, size, "/");
    else
        snprintf(dir, size, "%.*s", (int)(slash - path), path);
}

/* The folder of the target must exist and take new files. */
static rsmooth_status check_folder(const rs_output *o, const char *where, rsmooth_error *error) {
    char dir[RS_OUTPUT_PATH_MAX];
    folder_of(o->target, dir, sizeof dir);
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write there: '%s': %s", o->path,
                       dir, stat(dir, &st) != 0 ? strerror(errno) : "not a folder");
    if (access(dir, W_OK | X_OK) != 0)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write in folder '%s': %s",
                       o->path, dir, strerror(errno));
    return RSMOOTH_OK;
}

/* A link is written through, as cp does: the link stays and the file it names gets the result.
 * A link to nothing is refused even when replacing, since writing through it would create a file
 * wherever the link happens to point. */
static rsmooth_status follow_link(rs_output *o, const char *where, rsmooth_error *error) {
    o->link = true;
    char points_to[RS_OUTPUT_PATH_MAX];
    ssize_t n = readlink(o->path, points_to, sizeof points_to - 1);
    points_to[n > 0 ? n : 0] = '\0';
    char *resolved = realpath(o->path, NULL);
    if (!resolved || stat(resolved, &o->st) != 0) {
        int e = errno;
        free(resolved);
        if (e == ENOENT)
            return rs_fail(error, RSMOOTH_ERROR_IO, where,
                           "%s: is a symbolic link to '%s', which does not exist: not writing "
                           "through it (remove the link, or name the file to create)",
                           o->path, points_to);
        return rs_fail(error, RSMOOTH_ERROR_IO, where,
                       "%s: is a symbolic link to '%s' that cannot be followed: %s", o->path,
                       points_to, strerror(e));
    }
    bool fits = strlen(resolved) + sizeof PARTIAL_NAME < sizeof o->target;
    if (fits)
        strcpy(o->target, resolved);
    free(resolved);
    if (!fits)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: path of its target too long", o->path);
    return RSMOOTH_OK;
}

rsmooth_status rs_output_resolve(rs_output *o, const char *path, bool replace, const char *hint,
                                 const char *where, rsmooth_error *error) {
    memset(o, 0, sizeof *o);
    o->fd = -1;
    o->guard = -1;
    o->path = path;
    o->hint = hint;
    if (strlen(path) + sizeof PARTIAL_NAME >= sizeof o->target)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: path too long", path);
    strcpy(o->target, path);
    struct stat st;
    if (lstat(path, &st) != 0) {
        if (errno != ENOENT)
            return rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write there: %s", path,
                           strerror(errno));
        return check_folder(o, where, error);
    }
    o->exists = true;
    o->st = st;
    if (S_ISLNK(st.st_mode)) {
        rsmooth_status status = follow_link(o, where, error);
        if (status != RSMOOTH_OK)
            return status;
    }
    if (S_ISDIR(o->st.st_mode))
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: is a directory", path);
    if (!S_ISREG(o->st.st_mode))
        return rs_fail(error, RSMOOTH_ERROR_IO, where,
                       "%s: is not a regular file (a device, FIFO or socket): not replacing it",
                       path);
    if (!replace && o->link)
        return rs_fail(error, RSMOOTH_ERROR_IO, where,
                       "%s: already exists (a symbolic link to %s; %s to write the result "
                       "there)",
                       path, o->target, hint);
    if (!replace)
        return rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: already exists (%s to replace it)",
                       path, hint);
    if (o->st.st_nlink > 1) /* a new file replaces this name only */
        snprintf(o->notes, sizeof o->notes,
                 "the file has %ld hard links; only this name gets the result, the others keep "
                 "the old content",
                 (long)o->st.st_nlink);
    return check_folder(o, where, error);
}

/* ---- the new content ------------------------------------------------------------------------- */

/* `o->temporary` = the target's folder + `name`. */
static void temporary_beside(rs_output *o, const char *name) {
    char dir[RS_OUTPUT_PATH_MAX];
    folder_of(o->target, dir, sizeof dir);
    snprintf(o->temporary, sizeof o->temporary, "%s%s", strcmp(dir, "/") ? dir : "", name);
}

/* The X's at the end of o->temporary replaced by letters and digits (linkat cannot use mkstemp). */
static void fill_random_name(rs_output *o) {
    static const char letters[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    static _Thread_local uint64_t state;
    if (!state)
        state = (uint64_t)time(NULL) ^ ((uint64_t)getpid() << 32) ^ (uint64_t)(uintptr_t)&state;
    char *x = o->temporary + strlen(o->temporary) - 6;
    for (int i = 0; i < 6; i++) {
        state = state * 6364136223846793005u + 1442695040888963407u;
        x[i] = letters[(state >> 33) % (sizeof letters - 1)];
    }
}

/* An unnamed file in the target's folder: a kill leaves nothing behind. -1 where the system or
 * file system has none, or no /proc to link it by. */
static int open_unnamed(rs_output *o) {
#ifdef O_TMPFILE
    const char *named = rs_environment_now(RS_ENV_NAMED_TEMPORARY);
    if (named && strcmp(named, "1") == 0)
        return -1;
    char dir[RS_OUTPUT_PATH_MAX];
    folder_of(o->target, dir, sizeof dir);
    int fd = open(dir, O_TMPFILE | O_RDWR | O_CLOEXEC, 0666);
    if (fd < 0)
        return -1;
    snprintf(o->proc, sizeof o->proc, "/proc/self/fd/%d", fd);
    struct stat st;
    if (stat(o->proc, &st) != 0) {
        close(fd);
        o->proc[0] = '\0';
        return -1;
    }
    return fd;
#else
    (void)o;
    return -1;
#endif
}

/* The permissions a new file gets from the umask, read without changing it where Linux shows it
 * (/proc/self/status, "Umask:", since 4.7): umask() reads it only by setting it, and meanwhile
 * files that other threads of the process create get mode 0666. Elsewhere umask(), set back. */
static mode_t new_file_mode(void) {
    FILE *f = fopen("/proc/self/status", "re");
    if (f) {
        char line[256];
        unsigned mask = 0;
        bool found = false;
        while (!found && fgets(line, sizeof line, f))
            found = sscanf(line, "Umask: %o", &mask) == 1;
        fclose(f);
        if (found)
            return 0666 & ~(mode_t)mask;
    }
    mode_t mask = umask(0);
    umask(mask);
    return 0666 & ~mask;
}

/* Gives the new file the replaced one's owner, group and permission bits (chown first: it clears
 * set-user-ID bits). A user who may not give a file away keeps what they can, in a note. */
static int keep_owner_and_mode(rs_output *o) {
    const struct stat *old = &o->st;
    mode_t mode = old->st_mode & 07777;
    if (fchown(o->fd, old->st_uid, old->st_gid) != 0 &&
        fchown(o->fd, (uid_t)-1, old->st_gid) != 0) {
        /* neither: the new file keeps this user's owner and group, noted below */
    }
    struct stat now;
    if (fstat(o->fd, &now) != 0)
        return -1;
    if (now.st_uid != old->st_uid)
        mode &= ~(mode_t)S_ISUID; /* never a set-user-ID file of a different owner */
    if (now.st_gid != old->st_gid)
        mode &= ~(mode_t)S_ISGID;
    if (now.st_uid != old->st_uid || now.st_gid != old->st_gid) {
        size_t used = strlen(o->notes);
        snprintf(o->notes + used, sizeof o->notes - used,
                 "%sthe owner could not be kept: it was %ld:%ld, the result is %ld:%ld (only "
                 "root can give a file away); its mode %o is kept",
                 used ? "; " : "", (long)old->st_uid, (long)old->st_gid, (long)now.st_uid,
                 (long)now.st_gid, (unsigned)mode);
    }
    return fchmod(o->fd, mode);
}

/* The mode, owner and group the content must have: the replaced file's, or a new file's. */
static rsmooth_status set_permissions(rs_output *o, const char *where, rsmooth_error *error) {
    int r = o->exists ? keep_owner_and_mode(o) : fchmod(o->fd, new_file_mode());
    if (r != 0)
        return rs_fail(error, RSMOOTH_ERROR_IO, where,
                       "%s: cannot give the result the permissions of the file it replaces: %s",
                       o->path, strerror(errno));
    return RSMOOTH_OK;
}

rsmooth_status rs_output_create(rs_output *o, const char *where, rsmooth_error *error) {
    o->fd = open_unnamed(o);
    if (o->fd < 0) {
        o->proc[0] = '\0';
        temporary_beside(o, TEMPORARY_NAME);
        for (int attempt = 0; attempt < 100 && o->fd < 0; attempt++) {
            fill_random_name(o);
            /* guarded before it exists, so no signal can come between the two */
            o->guard = rs_guard_add(o->temporary);
            o->fd = open(o->temporary, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
            if (o->fd < 0) {
                rs_guard_remove(o->guard);
                o->guard = -1;
                if (errno != EEXIST)
                    break;
            }
        }
        if (o->fd < 0) {
            int e = errno;
            o->temporary[0] = '\0';
            return rs_fail(error, RSMOOTH_ERROR_IO, where,
                           "%s: cannot create a temporary file beside it: %s", o->path,
                           strerror(e));
        }
        o->own_temporary = true;
    }
    /* new files get the umask's mode (the temporary is made 0600), replacements the old one's */
    return set_permissions(o, where, error);
}

/* A 64-bit FNV-1a hash of the target's path: the partial file's name, the same in every process
 * that writes this output, and short whatever the output's name. */
static uint64_t path_hash(const char *path) {
    uint64_t h = 0xcbf29ce484222325u;
    for (const unsigned char *p = (const unsigned char *)path; *p; p++)
        h = (h ^ *p) * 0x100000001b3u;
    return h;
}

rsmooth_status rs_output_create_partial(rs_output *o, bool make, const char *where,
                                        rsmooth_error *error) {
    char name[sizeof PARTIAL_NAME];
    snprintf(name, sizeof name, "/.rsmooth-partial-%016llx",
             (unsigned long long)path_hash(o->target));
    temporary_beside(o, name);
    if (!make) {
        o->fd = open(o->temporary, O_RDWR | O_NOFOLLOW | O_CLOEXEC);
        struct stat st;
        if (o->fd >= 0 && (fstat(o->fd, &st) != 0 || !S_ISREG(st.st_mode))) {
            close(o->fd);
            o->fd = -1;
            errno = EINVAL;
        }
        if (o->fd < 0)
            return rs_fail(error, RSMOOTH_ERROR_IO, where,
                           "%s: cannot open the partial output %s: %s", o->path, o->temporary,
                           strerror(errno));
        return RSMOOTH_OK;
    }
    o->guard = rs_guard_add(o->temporary); /* before it exists: see rs_output_create */
    o->fd = open(o->temporary, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (o->fd < 0) {
        rs_guard_remove(o->guard);
        o->guard = -1;
        return rs_fail(error, RSMOOTH_ERROR_IO, where,
                       "%s: cannot create the partial output %s: %s%s", o->path, o->temporary,
                       strerror(errno),
                       errno == EEXIST ? " (another run is writing this output, or a run that "
                                         "was killed left it: remove it)"
                                       : "");
    }
    o->own_temporary = true;
    return set_permissions(o, where, error);
}

/* ---- putting it in place --------------------------------------------------------------------- */

/* rename(from, to) that fails with EEXIST instead of replacing `to`. */
static int rename_noreplace(const char *from, const char *to) {
#ifdef RENAME_NOREPLACE
    if (renameat2(AT_FDCWD, from, AT_FDCWD, to, RENAME_NOREPLACE) == 0)
        return 0;
    if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP)
        return -1;
#endif
    /* link() never replaces either, where the file system has hard links */
    if (link(from, to) == 0) {
        unlink(from);
        return 0;
    }
    if (errno != EPERM && errno != EOPNOTSUPP && errno != ENOSYS)
        return -1;
    /* Neither (e.g. FAT): look, then rename. A run creating `to` in between is replaced. */
    struct stat st;
    if (lstat(to, &st) == 0) {
        errno = EEXIST;
        return -1;
    }
    return rename(from, to);
}

/* Replacing with an unnamed file: linked under a temporary name (guarded), then renamed over the
 * target, which is atomic. The name exists only between the two calls. */
static int link_and_rename(rs_output *o) {
    temporary_beside(o, TEMPORARY_NAME);
    for (int attempt = 0; attempt < 100; attempt++) {
        fill_random_name(o);
        o->guard = rs_guard_add(o->temporary); /* before it exists: see rs_output_create */
        if (linkat(AT_FDCWD, o->proc, AT_FDCWD, o->temporary, AT_SYMLINK_FOLLOW) == 0) {
            o->own_temporary = true;
            return rename(o->temporary, o->target);
        }
        int e = errno;
        rs_guard_remove(o->guard);
        o->guard = -1;
        errno = e;
        if (e != EEXIST)
            break;
    }
    o->temporary[0] = '\0';
    return -1;
}

/* Puts the content at the target: 0, or -1 with errno (EEXIST: another file took the name and
 * `replace` is off). */
static int put_in_place(rs_output *o, bool replace) {
    if (!o->proc[0]) /* a named temporary or partial */
        return replace ? rename(o->temporary, o->target)
                       : rename_noreplace(o->temporary, o->target);
    if (!replace) /* linkat never replaces: the same guarantee as RENAME_NOREPLACE */
        return linkat(AT_FDCWD, o->proc, AT_FDCWD, o->target, AT_SYMLINK_FOLLOW);
    return link_and_rename(o);
}

rsmooth_status rs_output_publish(rs_output *o, bool replace, const char *where,
                                 rsmooth_error *error) {
    rsmooth_status status = RSMOOTH_OK;
    /* on disk before it replaces a file, so a crash cannot leave an empty file in its place */
    if (o->exists && fsync(o->fd) != 0)
        status = rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write: %s", o->path,
                         strerror(errno));
    bool placed = false;
    if (status == RSMOOTH_OK && put_in_place(o, replace) != 0) {
        if (errno == EEXIST && !replace)
            status = rs_fail(error, RSMOOTH_ERROR_IO, where,
                             "%s: already exists: another program created it while this run "
                             "was working (%s to replace it)",
                             o->path, o->hint);
        else
            status = rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write: %s", o->path,
                             strerror(errno));
    } else if (status == RSMOOTH_OK) {
        placed = true;
        o->temporary[0] = '\0'; /* renamed into place, or there was none */
    }
    /* after publishing, since an unnamed file is linked through its descriptor; a network file
     * system may report a failed write only now: then a new file is taken back out */
    int fd = o->fd;
    o->fd = -1;
    if (close(fd) != 0 && status == RSMOOTH_OK) {
        status = rs_fail(error, RSMOOTH_ERROR_IO, where, "%s: cannot write: %s", o->path,
                         strerror(errno));
        if (placed && !replace)
            unlink(o->target);
    }
    rs_output_discard(o);
    return status;
}

void rs_output_discard(rs_output *o) {
    if (o->fd >= 0)
        close(o->fd);
    o->fd = -1;
    if (o->own_temporary && o->temporary[0])
        unlink(o->temporary);
    o->temporary[0] = '\0';
    o->own_temporary = false;
    rs_guard_remove(o->guard);
    o->guard = -1;
}
