/* The rsmooth command's output files (see cli_output.h). */
#define _GNU_SOURCE /* O_TMPFILE, linkat, renameat2 and RENAME_NOREPLACE (Linux) */
#include "cli_output.h"
#include "cli_files.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

/* A short name, so an output name of 255 bytes (the usual limit) still has a temporary. */
#define TEMPORARY_NAME "/.rsmooth-XXXXXX"

/* The file an output path leads to. */
typedef struct output_target {
    char path[PATH_MAX]; /* `path`, or the final target of a symbolic link */
    bool exists, link;   /* whether it exists (then `st` describes it); whether `path` is a link */
    struct stat st;
} output_target;

/* The directory part of `path`: "." for a bare name, "/" for a file at the root. */
static void directory_of(const char *path, char *dir, size_t size) {
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, size, ".");
    else if (slash == path)
        snprintf(dir, size, "/");
    else
        snprintf(dir, size, "%.*s", (int)(slash - path), path);
}

/* -1 when the folder of `target` exists and this user may create files in it, else prints why
 * (naming `path`) and returns EXIT_USAGE: found before the work, not after it. */
static int check_folder(const char *path, const char *target) {
    char dir[PATH_MAX];
    directory_of(target, dir, sizeof dir);
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "rsmooth: %s: cannot write there: '%s': %s\n", path, dir,
                stat(dir, &st) != 0 ? strerror(errno) : "not a folder");
        return EXIT_USAGE;
    }
    if (access(dir, W_OK | X_OK) != 0) {
        fprintf(stderr, "rsmooth: %s: cannot write in folder '%s': %s\n", path, dir,
                strerror(errno));
        return EXIT_USAGE;
    }
    return -1;
}

/* Fills `t` for `path`; prints why and returns EXIT_USAGE when `path` may not be written. */
static int resolve_output(const char *path, bool replace, output_target *t) {
    memset(t, 0, sizeof *t);
    if (strlen(path) + sizeof TEMPORARY_NAME > sizeof t->path) {
        fprintf(stderr, "rsmooth: %s: path too long\n", path);
        return EXIT_USAGE;
    }
    struct stat st;
    if (lstat(path, &st) != 0) {
        if (errno != ENOENT) {
            fprintf(stderr, "rsmooth: %s: cannot write there: %s\n", path, strerror(errno));
            return EXIT_USAGE;
        }
        strcpy(t->path, path);
        return check_folder(path, t->path);
    }
    t->exists = true;
    t->st = st;
    strcpy(t->path, path);
    if (S_ISLNK(st.st_mode)) {
        /* Written through, as cp does: the link stays and the file it names gets the result. A
         * link to nothing is refused even with --force, since writing through it would create a
         * file wherever the link happens to point. */
        t->link = true;
        char target[PATH_MAX];
        ssize_t n = readlink(path, target, sizeof target - 1);
        target[n > 0 ? n : 0] = '\0';
        if (!realpath(path, t->path) || stat(t->path, &t->st) != 0) {
            if (errno == ENOENT)
                fprintf(stderr,
                        "rsmooth: %s: is a symbolic link to '%s', which does not exist: "
                        "not writing through it (remove the link, or name the file to "
                        "create)\n",
                        path, target);
            else
                fprintf(stderr,
                        "rsmooth: %s: is a symbolic link to '%s' that cannot be "
                        "followed: %s\n",
                        path, target, strerror(errno));
            return EXIT_USAGE;
        }
        if (strlen(t->path) + sizeof TEMPORARY_NAME > sizeof t->path) {
            fprintf(stderr, "rsmooth: %s: path of its target too long\n", path);
            return EXIT_USAGE;
        }
    }
    if (S_ISDIR(t->st.st_mode)) {
        fprintf(stderr, "rsmooth: %s: is a directory\n", path);
        return EXIT_USAGE;
    }
    if (!S_ISREG(t->st.st_mode)) {
        fprintf(stderr, "rsmooth: %s: is not a regular file: not replacing it\n", path);
        return EXIT_USAGE;
    }
    if (!replace && t->link) {
        fprintf(stderr,
                "rsmooth: %s: already exists (a symbolic link to %s; use --force to "
                "write the result there)\n",
                path, t->path);
        return EXIT_USAGE;
    }
    if (!replace) {
        fprintf(stderr, "rsmooth: %s: already exists (use --force to replace it)\n", path);
        return EXIT_USAGE;
    }
    return check_folder(path, t->path);
}

int cli_check_output_path(const char *path, bool replace) {
    output_target t;
    return resolve_output(path, replace, &t);
}

bool cli_same_file(const char *a, const char *b) {
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* The named temporary, removed if a signal interrupts the command while it exists. */
static volatile sig_atomic_t have_temporary;
static char temporary[PATH_MAX + sizeof TEMPORARY_NAME];

static void remove_temporary_and_exit(int signal_number) {
    if (have_temporary)
        unlink(temporary);
    signal(signal_number, SIG_DFL);
    raise(signal_number);
}

static void catch_signals(void (*handler)(int)) {
    signal(SIGINT, handler);
    signal(SIGTERM, handler);
    signal(SIGHUP, handler);
}

/* `temporary` = the directory of `path` + TEMPORARY_NAME (the X's still to fill). */
static void temporary_beside(const char *path) {
    char dir[PATH_MAX];
    directory_of(path, dir, sizeof dir);
    snprintf(temporary, sizeof temporary, "%s" TEMPORARY_NAME, strcmp(dir, "/") ? dir : "");
}

/* The X's of `temporary` replaced by letters and digits (for linkat, which mkstemp cannot name). */
static void fill_temporary_name(void) {
    static const char letters[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    static uint64_t state;
    if (!state)
        state = (uint64_t)time(NULL) ^ ((uint64_t)getpid() << 32) ^ (uint64_t)(uintptr_t)&state;
    char *x = temporary + strlen(temporary) - 6;
    for (int i = 0; i < 6; i++) {
        state = state * 6364136223846793005u + 1442695040888963407u;
        x[i] = letters[(state >> 33) % (sizeof letters - 1)];
    }
}

/* An unnamed file in the directory of `path` (O_TMPFILE): a kill leaves nothing behind. -1 where
 * the system or file system has none (EOPNOTSUPP, EISDIR, EINVAL), or no /proc to link it by. */
static int open_unnamed(const char *path, char *proc, size_t proc_size) {
#ifdef O_TMPFILE
    const char *named = getenv("RSMOOTH_NAMED_TEMPORARY");
    if (named && strcmp(named, "1") == 0)
        return -1;
    char dir[PATH_MAX];
    directory_of(path, dir, sizeof dir);
    int fd = open(dir, O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    if (fd < 0)
        return -1;
    snprintf(proc, proc_size, "/proc/self/fd/%d", fd);
    struct stat st;
    if (stat(proc, &st) != 0) {
        close(fd);
        return -1;
    }
    return fd;
#else
    (void)path, (void)proc, (void)proc_size;
    return -1;
#endif
}

/* ".rsmooth-XXXXXX" in the directory of `path`, with the permissions a new file gets. */
static int open_named(const char *path) {
    temporary_beside(path);
    int fd = mkstemp(temporary);
    if (fd < 0)
        return -1;
    have_temporary = 1;
    mode_t mask = umask(0); /* mkstemp makes 0600 files; give the usual permissions */
    umask(mask);
    if (fchmod(fd, 0666 & ~mask) != 0) {
        int e = errno;
        unlink(temporary);
        have_temporary = 0;
        close(fd);
        errno = e;
        return -1;
    }
    return fd;
}

/* Gives the new file the replaced one's owner, group and permission bits (chown first: it clears
 * set-user-ID bits). A user who may not give a file away keeps what they can and is told. */
static int keep_owner_and_mode(int fd, const struct stat *old, const char *path, bool quiet) {
    mode_t mode = old->st_mode & 07777;
    if (fchown(fd, old->st_uid, old->st_gid) != 0 && fchown(fd, (uid_t)-1, old->st_gid) != 0) {
        /* neither: the new file keeps this user's owner and group, said below */
    }
    struct stat now;
    if (fstat(fd, &now) != 0)
        return -1;
    if (now.st_uid != old->st_uid)
        mode &= ~(mode_t)S_ISUID; /* never a set-user-ID file of a different owner */
    if (now.st_gid != old->st_gid)
        mode &= ~(mode_t)S_ISGID;
    if ((now.st_uid != old->st_uid || now.st_gid != old->st_gid) && !quiet)
        fprintf(stderr,
                "rsmooth: %s: warning: the owner could not be kept: it was %ld:%ld, the "
                "result is %ld:%ld (only root can give a file away); its mode %o is kept\n",
                path, (long)old->st_uid, (long)old->st_gid, (long)now.st_uid, (long)now.st_gid,
                (unsigned)mode);
    return fchmod(fd, mode);
}

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

/* Puts the complete file in place at `target`. 0, or -1 with errno (EEXIST: another file took the
 * name and `replace` is off). */
static int publish(const char *proc, const char *target, bool replace) {
    if (!proc) /* the named temporary */
        return replace ? rename(temporary, target) : rename_noreplace(temporary, target);
    if (!replace) /* linkat never replaces: the same guarantee as RENAME_NOREPLACE */
        return linkat(AT_FDCWD, proc, AT_FDCWD, target, AT_SYMLINK_FOLLOW);
    /* Replacing: link under a temporary name, then rename over the target, which is atomic. The
     * name exists only between the two calls. */
    temporary_beside(target);
    for (int attempt = 0; attempt < 100; attempt++) {
        fill_temporary_name();
        if (linkat(AT_FDCWD, proc, AT_FDCWD, temporary, AT_SYMLINK_FOLLOW) == 0) {
            have_temporary = 1;
            return rename(temporary, target);
        }
        if (errno != EEXIST)
            return -1;
    }
    return -1;
}

int cli_write_atomically(const char *path, bool replace, bool quiet, cli_writer write, void *user) {
    output_target t;
    if (replace) {
        int code = resolve_output(path, true, &t);
        if (code >= 0)
            return code;
    } else if (strlen(path) + sizeof TEMPORARY_NAME > sizeof t.path) {
        fprintf(stderr, "rsmooth: %s: path too long\n", path);
        return EXIT_USAGE;
    } else {
        /* Not looked at again: whatever exists at `path` once the file is complete (another
         * run's result, a link) makes the final no-replace step fail, which is the one check
         * that no other run can slip past. */
        memset(&t, 0, sizeof t);
        strcpy(t.path, path);
    }
    /* A new file replaces this name only: say so where other names share the old one. */
    if (t.exists && t.st.st_nlink > 1 && !quiet)
        fprintf(stderr,
                "rsmooth: %s: warning: the file has %ld hard links; only this name gets "
                "the result, the others keep the old content\n",
                path, (long)t.st.st_nlink);
    catch_signals(remove_temporary_and_exit);
    char proc[64];
    const char *unnamed = proc;
    int fd = open_unnamed(t.path, proc, sizeof proc);
    if (fd < 0) {
        unnamed = NULL;
        fd = open_named(t.path);
    }
    char message[256] = "";
    if (fd < 0) {
        fprintf(stderr, "rsmooth: %s: cannot create a temporary file beside it: %s\n", path,
                strerror(errno));
        catch_signals(SIG_DFL);
        return EXIT_OTHER;
    }
    bool ok = true;
    if (t.exists && keep_owner_and_mode(fd, &t.st, path, quiet) != 0) {
        snprintf(message, sizeof message,
                 "cannot give it the permissions of the file it "
                 "replaces: %s",
                 strerror(errno));
        ok = false;
    }
    FILE *f = ok ? fdopen(fd, "wb") : NULL;
    if (ok && !f) {
        snprintf(message, sizeof message, "%s", strerror(errno));
        ok = false;
    }
    if (ok)
        ok = write(f, user, message, sizeof message) == 0;
    if (ok && (fflush(f) != 0 || ferror(f))) {
        snprintf(message, sizeof message, "%s", strerror(errno));
        ok = false;
    }
    /* On disk before it replaces a file, so a crash cannot leave an empty file in its place. */
    if (ok && t.exists && fsync(fd) != 0) {
        snprintf(message, sizeof message, "%s", strerror(errno));
        ok = false;
    }
    bool taken = false; /* another run created the file meanwhile */
    if (ok && publish(unnamed, t.path, replace) != 0) {
        taken = errno == EEXIST && !replace;
        snprintf(message, sizeof message, "%s", strerror(errno));
        ok = false;
    }
    /* After publishing, since the unnamed file is linked through its descriptor. A network file
     * system may report a failed write only now: then a new file is taken back out. */
    if ((f ? fclose(f) : close(fd)) != 0 && ok) {
        snprintf(message, sizeof message, "%s", strerror(errno));
        ok = false;
        if (!replace)
            unlink(t.path);
    }
    if (taken)
        fprintf(stderr,
                "rsmooth: %s: already exists: another program created it while this "
                "run was working (use --force to replace it)\n",
                path);
    else if (!ok)
        fprintf(stderr, "rsmooth: %s: cannot write: %s\n", path, message);
    if (!ok && have_temporary)
        unlink(temporary);
    have_temporary = 0;
    catch_signals(SIG_DFL);
    return ok ? EXIT_OK : taken ? EXIT_USAGE : EXIT_OTHER;
}
