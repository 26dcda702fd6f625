/* The file-system calls Fortran cannot make on its own: glue for ropedyn_os.f90, which is
 * the only caller.
 *
 * - What a path is (stat or lstat): a regular file, a directory, a FIFO, a device, ... so
 *   that an input that would block a reader (a FIFO) or never end (/dev/zero) is refused
 *   before it is opened.
 * - The identity of a file (device and inode, symbolic links followed) and the canonical
 *   form of a path (realpath), to tell whether two names are one file.
 * - The system's text of an errno value (strerror_r).
 * - The process that holds a lock on a file (flock or fcntl), from /proc/locks: the HDF5
 *   library locks the files it opens, and a second opener is told only "cannot lock".
 * - A new file that appears whole or not at all (a lock and who holds it): written unnamed,
 *   then linked into place, which fails when the name exists. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/types.h>
#include <unistd.h>

/* The kinds of ropedyn_file_kind (the same numbers as FILE_* in ropedyn_os.f90). */
enum { KIND_MISSING = 0, KIND_REGULAR, KIND_DIRECTORY, KIND_FIFO, KIND_CHAR_DEVICE,
       KIND_BLOCK_DEVICE, KIND_SOCKET, KIND_SYMLINK, KIND_OTHER };

/* What `path` is, symbolic links followed when `follow` (else a link is KIND_SYMLINK);
 * KIND_MISSING with errno in `err` when it cannot be had (no such file, a loop, ...). */
int ropedyn_file_kind(const char *path, int follow, int *err)
{
    struct stat st;
    *err = 0;
    if ((follow ? stat(path, &st) : lstat(path, &st)) != 0) {
        *err = errno;
        return KIND_MISSING;
    }
    if (S_ISREG(st.st_mode)) return KIND_REGULAR;
    if (S_ISDIR(st.st_mode)) return KIND_DIRECTORY;
    if (S_ISFIFO(st.st_mode)) return KIND_FIFO;
    if (S_ISCHR(st.st_mode)) return KIND_CHAR_DEVICE;
    if (S_ISBLK(st.st_mode)) return KIND_BLOCK_DEVICE;
    if (S_ISSOCK(st.st_mode)) return KIND_SOCKET;
    if (S_ISLNK(st.st_mode)) return KIND_SYMLINK;
    return KIND_OTHER;
}

/* mkdir(2) of `path` with `mode`. Returns 0, or errno. */
int ropedyn_mkdir(const char *path, int mode)
{
    return mkdir(path, (mode_t)mode) == 0 ? 0 : errno;
}

/* The device and inode of `path` (links followed). Returns 0, or errno. */
int ropedyn_file_id(const char *path, long long *dev, long long *ino)
{
    struct stat st;
    if (stat(path, &st) != 0) return errno;
    *dev = (long long)st.st_dev;
    *ino = (long long)st.st_ino;
    return 0;
}

/* The canonical absolute form of `path` (realpath: every link resolved) in `buf` of
 * `size` bytes, NUL-terminated. Returns 0, or errno (ENAMETOOLONG when it does not fit). */
int ropedyn_real_path(const char *path, char *buf, int size)
{
    char *full = realpath(path, NULL);
    size_t n;
    if (!full) return errno;
    n = strlen(full);
    if (n + 1 > (size_t)size) {
        free(full);
        return ENAMETOOLONG;
    }
    memcpy(buf, full, n + 1);
    free(full);
    return 0;
}

/* The target of the symbolic link `path` as the link holds it (relative to the link's
 * directory when it is relative) in `buf` of `size` bytes, NUL-terminated. Returns 0, or
 * errno (EINVAL: not a link). */
int ropedyn_link_target(const char *path, char *buf, int size)
{
    ssize_t n;
    if (size < 1) return ENAMETOOLONG;
    n = readlink(path, buf, (size_t)size);
    if (n < 0) return errno;
    if (n >= size) return ENAMETOOLONG;
    buf[n] = '\0';
    return 0;
}

/* The system's text of `errnum` in `buf` of `size` bytes, NUL-terminated. */
void ropedyn_errno_text(int errnum, char *buf, int size)
{
    const char *text;
    char scratch[256];
    if (size < 1) return;
    text = strerror_r(errnum, scratch, sizeof scratch);   /* GNU: returns the text */
    snprintf(buf, (size_t)size, "%s", text ? text : "unknown error");
}

/* The process that holds a lock on the file `path` (a flock, a POSIX or an OFD lock, as
 * /proc/locks lists them by device and inode): its pid, 0 when none holds one, -1 when it
 * cannot be told (no /proc/locks, no such file, or an OFD lock, which has no pid). A lock
 * held by this process itself is not counted. */
int ropedyn_lock_holder(const char *path)
{
    struct stat st;
    char line[512];
    FILE *locks;
    int holder = 0;
    pid_t self = getpid();
    if (stat(path, &st) != 0) return -1;
    locks = fopen("/proc/locks", "re");
    if (!locks) return -1;
    while (fgets(line, sizeof line, locks)) {
        char kind[16], mode[16], access[16];
        unsigned int major, minor;
        unsigned long long inode;
        int pid;
        /* "1: FLOCK  ADVISORY  WRITE 4711 08:01:131 0 EOF"; a waiter has "->" first */
        if (strstr(line, "->")) continue;
        if (sscanf(line, "%*d: %15s %15s %15s %d %x:%x:%llu", kind, mode, access, &pid,
                   &major, &minor, &inode) != 7)
            continue;
        if (major != major(st.st_dev) || minor != minor(st.st_dev) ||
            inode != (unsigned long long)st.st_ino)
            continue;
        if (pid == (int)self) continue;
        holder = pid > 0 ? pid : -1;
        if (pid > 0) break;
    }
    fclose(locks);
    return holder;
}

/* Whether the file `path` can be locked exclusively now (flock, not waiting): 0 yes (the
 * lock is released at once), EWOULDBLOCK when another process holds a lock on it, else
 * errno (no such file: ENOENT). Opens the file without truncating or creating it. */
int ropedyn_try_lock(const char *path)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY), rc = 0;
    if (fd < 0) return errno;
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) rc = errno;
    else flock(fd, LOCK_UN);
    close(fd);
    return rc;
}

/* Room kept on the file system for the file `path`: its blocks from offset 0 to its end
 * (or to `end`, when that is further: the writer's idea of it) plus `bytes` allocated
 * (fallocate, FALLOC_FL_KEEP_SIZE: its size is unchanged), so that writes there cannot fail
 * for want of space. Returns 0, or errno: ENOSPC (or EDQUOT) when the file system has not
 * that much room left, EFBIG when the process's file-size limit (RLIMIT_FSIZE) is nearer;
 * EOPNOTSUPP where it cannot reserve. */
int ropedyn_reserve_space(const char *path, long long end, long long bytes)
{
    struct stat st;
    struct rlimit limit;
    off_t last;
    int fd = open(path, O_WRONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY), rc = 0;
    if (fd < 0) return errno;
    if (fstat(fd, &st) != 0) rc = errno;
    last = st.st_size > (off_t)end ? st.st_size : (off_t)end;
    /* a file-size limit (ulimit -f) is room that cannot be had either */
    if (rc == 0 && getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
        (unsigned long long)(last + (off_t)bytes) > (unsigned long long)limit.rlim_cur)
        rc = EFBIG;
    if (rc == 0 && fallocate(fd, FALLOC_FL_KEEP_SIZE, 0, last + (off_t)bytes) != 0) rc = errno;
    close(fd);
    return rc;
}

/* Give back the room reserved beyond the end of the file `path` (ropedyn_reserve_space).
 * Returns 0, or errno. */
int ropedyn_release_space(const char *path)
{
    struct stat st;
    int fd = open(path, O_WRONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY), rc = 0;
    if (fd < 0) return errno;
    if (fstat(fd, &st) != 0) rc = errno;
    else if (ftruncate(fd, st.st_size) != 0) rc = errno;
    close(fd);
    return rc;
}

/* Write all `len` bytes of `text` to `fd`; 0 or errno. */
static int write_all(int fd, const char *text, int len)
{
    while (len > 0) {
        ssize_t done = write(fd, text, (size_t)len);
        if (done < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        text += done;
        len -= (int)done;
    }
    return 0;
}

/* Whether errno `rc` says that a way of making a file does not work here (no /proc, a file
 * system without such files or links), so that the next is tried. */
static int no_such_way(int rc)
{
    return rc == ENOENT || rc == EPERM || rc == EOPNOTSUPP || rc == ENOSYS || rc == EXDEV ||
           rc == EMLINK || rc == EINVAL;
}

/* The new file `path` created with the contents `text` (`len` bytes) only if no file of
 * that name exists, and never seen without them: 0 created, EEXIST when `path` exists, else
 * errno. A process killed at any point leaves no `path`, or `path` whole.
 * - Written to an unnamed file in the directory (O_TMPFILE), then given its name
 *   (linkat, which fails with EEXIST when the name exists): nothing is left behind by a kill.
 * - Where there are no unnamed files (NFS): written to `path`.HOST.PID.new, linked to
 *   `path` (an exclusive creation also on NFS), then removed; a kill in between leaves that
 *   file, never a part of `path`.
 * - Where there are no hard links either: created exclusively and written (O_EXCL), as
 *   before; a kill between the two leaves `path` empty. */
int ropedyn_create_whole(const char *path, const char *text, int len)
{
    char dir[PATH_MAX], proc[64], host[256], temp[PATH_MAX + 320];
    int fd, rc;
    struct stat st;
    if (snprintf(dir, sizeof dir, "%s", path) >= (int)sizeof dir) return ENAMETOOLONG;
    fd = open(dirname(dir), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    if (fd >= 0) {
        rc = write_all(fd, text, len);
        snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
        if (rc == 0 && linkat(AT_FDCWD, proc, AT_FDCWD, path, AT_SYMLINK_FOLLOW) != 0)
            rc = errno;
        close(fd);
        if (!no_such_way(rc)) return rc;
    }
    if (gethostname(host, sizeof host) != 0) snprintf(host, sizeof host, "host");
    host[sizeof host - 1] = '\0';
    snprintf(temp, sizeof temp, "%s.%s.%ld.new", path, host, (long)getpid());
    fd = open(temp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) return errno;
    rc = write_all(fd, text, len);
    if (close(fd) != 0 && rc == 0) rc = errno;
    if (rc == 0 && link(temp, path) != 0) {
        rc = errno;
        /* over NFS a link can be made and its reply lost: the count of links tells */
        if (rc != EEXIST && stat(temp, &st) == 0 && st.st_nlink == 2) rc = 0;
    }
    unlink(temp);
    if (!no_such_way(rc)) return rc;
    fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) return errno;
    rc = write_all(fd, text, len);
    if (close(fd) != 0 && rc == 0) rc = errno;
    if (rc != 0) unlink(path);
    return rc;
}
