/* voiga's calls into the C library (Linux, glibc), with their constants, types and
 * macros from the system headers: the Fortran side never sees a flag value, a
 * signal or limit number, or a struct layout.
 *
 * Behind os.f90 and lock.f90: what is at a path (its kind, device, inode, links,
 * size), files created without following links and without replacing anything
 * (O_CREAT | O_EXCL | O_NOFOLLOW), existing files opened only when they are
 * regular files (a FIFO or a device node is refused, without blocking on it),
 * flock, renames that must not replace their target (renameat2 RENAME_NOREPLACE,
 * else link and unlink), disk space reserved beyond a file's end (fallocate),
 * errno, NAME_MAX and PATH_MAX. Behind process.f90: the soft limits on address
 * space and file size (getrlimit), SIGXFSZ ignored, whether standard output is a
 * terminal. Behind signals.f90: SIGINT and SIGTERM caught into a flag. Behind
 * heap.f90: glibc's malloc thresholds (mallopt).
 *
 * The file calls return 0, a count or a descriptor on success and -errno on
 * failure. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <malloc.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

/* What a path names; the values are those of os.f90's kind_* constants. */
enum { KIND_MISSING = 0, KIND_REGULAR, KIND_FOLDER, KIND_LINK, KIND_FIFO, KIND_CHAR, KIND_BLOCK, KIND_SOCKET };

static int kind_of(mode_t mode)
{
    if (S_ISREG(mode)) return KIND_REGULAR;
    if (S_ISDIR(mode)) return KIND_FOLDER;
    if (S_ISLNK(mode)) return KIND_LINK;
    if (S_ISFIFO(mode)) return KIND_FIFO;
    if (S_ISCHR(mode)) return KIND_CHAR;
    if (S_ISBLK(mode)) return KIND_BLOCK;
    return KIND_SOCKET;
}

static int described(const struct stat *st, int64_t *out)
{
    out[0] = (int64_t)st->st_dev;
    out[1] = (int64_t)st->st_ino;
    out[2] = (int64_t)st->st_nlink;
    out[3] = (int64_t)st->st_size;
    return kind_of(st->st_mode);
}

/* The kind of what `path` names (the link itself when `follow` is 0), and in
 * `out` its device, inode, number of links and size; KIND_MISSING when nothing is
 * there. */
int voiga_file_status(const char *path, int follow, int64_t *out)
{
    struct stat st;
    memset(out, 0, 4 * sizeof(*out));
    if ((follow ? stat(path, &st) : lstat(path, &st)) != 0) return errno == ENOENT ? KIND_MISSING : -errno;
    return described(&st, out);
}

/* The same for an open descriptor. */
int voiga_fd_status(int fd, int64_t *out)
{
    struct stat st;
    memset(out, 0, 4 * sizeof(*out));
    if (fstat(fd, &st) != 0) return -errno;
    return described(&st, out);
}

/* A new regular file at `path`, open for reading and writing (rw-r--r-- before the
 * umask): never through a symbolic link, never over anything that is there
 * (EEXIST). */
int voiga_create_new(const char *path)
{
    int fd = open(path, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, S_IRUSR | S_IWUSR | S_IRGRP | S_IROTH);
    return fd >= 0 ? fd : -errno;
}

/* The existing regular file `path`, opened read-only or (`writable`) read-write,
 * the last component not followed unless `follow`. O_NONBLOCK keeps the open of a
 * FIFO from waiting for its other end; anything but a regular file is closed
 * again and refused with -EINVAL. `kind` says what was there. */
int voiga_open_regular(const char *path, int writable, int follow, int *kind)
{
    int64_t info[4];
    int flags = (writable ? O_RDWR : O_RDONLY) | O_NONBLOCK | O_NOCTTY | O_CLOEXEC | (follow ? 0 : O_NOFOLLOW);
    int fd = open(path, flags), e;
    if (fd < 0) {
        e = errno;
        *kind = voiga_file_status(path, follow, info);
        return -e;
    }
    *kind = voiga_fd_status(fd, info);
    if (*kind != KIND_REGULAR || fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0) {
        close(fd);
        return -EINVAL;
    }
    return fd;
}

/* flock `how` (0 release, 1 shared, 2 exclusive) on `fd`, waiting for it when
 * `wait`: 0 taken, 1 another process holds it (without waiting), else -errno. */
int voiga_lock(int fd, int how, int wait)
{
    int op = how == 0 ? LOCK_UN : how == 1 ? LOCK_SH : LOCK_EX;
    if (!wait) op |= LOCK_NB;
    while (flock(fd, op) != 0) {
        if (errno == EINTR) continue;
        return errno == EWOULDBLOCK ? 1 : -errno;
    }
    return 0;
}

int voiga_close(int fd)
{
    return close(fd) == 0 ? 0 : -errno;
}

/* Write the whole of `text` (`n` bytes) at the start of `fd`, cutting the file there. */
int voiga_write_text(int fd, const char *text, int n)
{
    int at = 0;
    if (ftruncate(fd, 0) != 0) return -errno;
    while (at < n) {
        ssize_t w = pwrite(fd, text + at, (size_t)(n - at), at);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return w < 0 ? -errno : -EIO;
        at += (int)w;
    }
    return 0;
}

/* Read at most `n` bytes from the start of `fd`: the count read. */
int voiga_read_text(int fd, char *text, int n)
{
    ssize_t r;
    do r = pread(fd, text, (size_t)n, 0); while (r < 0 && errno == EINTR);
    return r >= 0 ? (int)r : -errno;
}

int voiga_unlink(const char *path)
{
    return unlink(path) == 0 ? 0 : -errno;
}

/* Rename `from` to `to`. With `replace` 0 an existing `to` is never replaced
 * (-EEXIST): renameat2's RENAME_NOREPLACE, or on a file system without it a hard
 * link (which fails on an existing name) and the removal of `from`. */
int voiga_rename(const char *from, const char *to, int replace)
{
    if (replace) return rename(from, to) == 0 ? 0 : -errno;
    if (renameat2(AT_FDCWD, from, AT_FDCWD, to, RENAME_NOREPLACE) == 0) return 0;
    if (errno != EINVAL && errno != ENOSYS) return -errno;
    if (link(from, to) != 0) return -errno;
    return unlink(from) == 0 ? 0 : -errno;
}

/* Reserve `bytes` of disk beyond the end of the file open as `fd` (its size
 * unchanged): 0, or -errno (a file system that cannot reserve space is not an
 * error: 0). */
int voiga_reserve(int fd, int64_t bytes)
{
    struct stat st;
    if (fstat(fd, &st) != 0) return -errno;
    if (fallocate(fd, FALLOC_FL_KEEP_SIZE, st.st_size, (off_t)bytes) == 0) return 0;
    return errno == EOPNOTSUPP ? 0 : -errno;
}

/* Give back what `voiga_reserve` reserved and the writes did not use: the file
 * cut to its own size. */
int voiga_release(int fd)
{
    struct stat st;
    if (fstat(fd, &st) != 0) return -errno;
    return ftruncate(fd, st.st_size) == 0 ? 0 : -errno;
}

/* The text of error number `e`. */
const char *voiga_strerror(int e)
{
    return strerror(e);
}

/* ENOENT, which realpath's caller tells apart from other failures. */
int voiga_enoent(void)
{
    return ENOENT;
}

/* EEXIST: an exclusive creation found something at its name. */
int voiga_eexist(void)
{
    return EEXIST;
}

/* The longest name of a file in a folder (NAME_MAX, bytes). */
int voiga_name_max(void)
{
    return NAME_MAX;
}

/* The longest path (PATH_MAX, bytes with the terminating zero). */
int voiga_path_max(void)
{
    return PATH_MAX;
}

/* The current errno (glibc keeps it per thread behind a function: no Fortran
 * binding to that function's name). */
int voiga_errno(void)
{
    return errno;
}

/* The soft limit `resource` (bytes), or -1 when it is unlimited or unknown. */
static int64_t soft_limit(int resource)
{
    struct rlimit limit;
    if (getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return -1;
    return limit.rlim_cur > (rlim_t)INT64_MAX ? INT64_MAX : (int64_t)limit.rlim_cur;
}

/* The address-space limit (`ulimit -v`, RLIMIT_AS) in bytes; -1: none. */
int64_t voiga_address_space_limit(void)
{
    return soft_limit(RLIMIT_AS);
}

/* The file-size limit (`ulimit -f`, RLIMIT_FSIZE) in bytes; -1: none. */
int64_t voiga_file_size_limit(void)
{
    return soft_limit(RLIMIT_FSIZE);
}

/* A write beyond the file-size limit fails with EFBIG instead of killing the
 * process with SIGXFSZ. */
void voiga_ignore_file_size_signal(void)
{
    signal(SIGXFSZ, SIG_IGN);
}

/* 1 when standard output is a terminal. */
int voiga_stdout_is_terminal(void)
{
    return isatty(STDOUT_FILENO);
}

/* The last SIGINT or SIGTERM caught since the start or the last
 * voiga_clear_signal (0: none). */
static volatile sig_atomic_t caught_signal = 0;

/* Record the signal and restore the default action, so that a second Ctrl-C ends
 * a run stuck in a long factorization at once. Both are async-signal safe. */
static void on_signal(int signum)
{
    caught_signal = signum;
    signal(signum, SIG_DFL);
}

/* Route SIGINT and SIGTERM to the flag. */
void voiga_catch_signals(void)
{
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
}

int voiga_caught_signal(void)
{
    return caught_signal;
}

void voiga_clear_signal(void)
{
    caught_signal = 0;
}

int voiga_sigint(void)
{
    return SIGINT;
}

int voiga_sigterm(void)
{
    return SIGTERM;
}

/* glibc's mmap and trim thresholds both raised to `bytes` (heap.f90 says why):
 * 1 when glibc took both. */
int voiga_keep_freed_memory(int bytes)
{
    int ok = mallopt(M_MMAP_THRESHOLD, bytes) == 1;
    return (mallopt(M_TRIM_THRESHOLD, bytes) == 1) && ok;
}
