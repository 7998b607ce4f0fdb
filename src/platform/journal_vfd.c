/* voiga's HDF5 file driver for result files: POSIX I/O like HDF5's sec2 driver, but
 * the file on disk changes only at a flush, and a flush is journaled, so a process
 * killed at any instant leaves a file that is either as it was after the last
 * completed flush or can be brought there (docs/hdf5.md, "Crash safety").
 *
 * Between flushes every write HDF5 issues is kept in memory (reads see it). A flush
 *   1. appends the kept writes to the end of the file as a journal: records
 *      (address, size, bytes), then a footer (magic, where the journal starts, its
 *      length, the file's size after the flush, the CRC-32 of the records);
 *   2. writes the kept writes at their addresses;
 *   3. truncates the file to its size after the flush, which removes the journal.
 * Killed before the footer is complete, the file is the previous one plus bytes
 * beyond its end, which HDF5 ignores; killed after, `voiga_journal_recover` (voiga
 * when it claims a result file, post's reader in Python: post/journal.py) finds the
 * footer and does steps 2 and 3 again. Against a kill, not against power loss:
 * nothing is fsync'ed.
 *
 * Test hook: VOIGA_JOURNAL_KILL=n sends the process SIGKILL in the n-th flush that
 * writes anything, after the first write of its step 2 (test/python/test_journal.py;
 * never set otherwise).
 *
 * Built against the installed HDF5's own headers (`<hdf5.h>`, its folder from
 * pkg-config through fpm's hdf5 metapackage) and written for HDF5 1.10; the driver
 * class is filled by field name, so a field HDF5 renames or removes is a compile
 * error, one it adds is left zero (NULL: not provided), and a callback whose
 * signature changed is an error too (the pragma below). HDF5 1.13.2 and later also
 * want the class's struct version and a driver value: set when
 * H5FD_CLASS_VERSION says the struct has them. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>
#include <hdf5.h>
#if defined(__has_include)
#if __has_include(<H5FDdevelop.h>)
#include <H5FDdevelop.h> /* H5FD_class_t and H5FD_t since HDF5 1.13 (1.10: H5FDpublic.h) */
#endif
#endif
#if !H5_VERSION_GE(1, 10, 0)
#error "voiga's journaled driver needs HDF5 1.10 or later"
#endif

/* A callback whose type does not match its field in the installed HDF5 is an
 * error, not a warning: HDF5 would call it with other arguments. */
#pragma GCC diagnostic error "-Wincompatible-pointer-types"

#define JOURNAL_MAGIC "VOIGAJ01"
#define FOOTER_BYTES 40
#define MAX_ADDR ((haddr_t)(((uint64_t)1 << 62) - 1))

typedef struct {
    haddr_t addr;
    size_t size;
    unsigned char *bytes;
} pending_t;

typedef struct {
    H5FD_t pub; /* must be first */
    int fd;
    haddr_t eoa, eof; /* eof: the file's size as HDF5 sees it (kept writes included) */
    dev_t device;
    ino_t inode;
    pending_t *kept;
    size_t n_kept, cap_kept;
    long kill_at, commits; /* test hook: the flush to be killed in (< 0: none), flushes so far */
} journal_file_t;

static hid_t driver_id = -1;

/* CRC-32 (IEEE 802.3, the polynomial of zlib's crc32 and Python's zlib.crc32, which
 * post/journal.py checks) of `n` bytes, by zlib, whose length argument is 32 bits
 * wide: a journal of 4 GiB or more goes through in pieces (crc32 continues from
 * the value of the previous piece). */
static uint64_t crc32_of(const unsigned char *p, size_t n)
{
    uLong c = crc32(0L, Z_NULL, 0);
    while (n > 0) {
        uInt piece = n > UINT_MAX ? UINT_MAX : (uInt)n;
        c = crc32(c, p, piece);
        p += piece;
        n -= piece;
    }
    return (uint64_t)c;
}

static int write_all(int fd, const void *buf, size_t n, off_t at)
{
    const unsigned char *p = buf;
    while (n > 0) {
        ssize_t w = pwrite(fd, p, n, at);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        p += w;
        n -= (size_t)w;
        at += w;
    }
    return 0;
}

static int read_all(int fd, void *buf, size_t n, off_t at)
{
    unsigned char *p = buf;
    while (n > 0) {
        ssize_t r = pread(fd, p, n, at);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return -1;
        if (r == 0) { /* beyond the end: zeros */
            memset(p, 0, n);
            return 0;
        }
        p += r;
        n -= (size_t)r;
        at += r;
    }
    return 0;
}

static void put64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t get64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--) v = (v << 8) | p[i];
    return v;
}

/* The existing regular file `path` opened with `oflags`, never through a symbolic
 * link, and never waiting on a FIFO (O_NONBLOCK while it is opened): anything but a
 * regular file is refused (-1). */
static int open_regular(const char *path, int oflags)
{
    struct stat st;
    int fd = open(path, oflags | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY);
    if (fd < 0) return -1;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

/* Steps 2 and 3 from a journal in memory (records of `length` bytes). */
static int apply_records(int fd, const unsigned char *rec, uint64_t length, uint64_t final_size,
                         int kill)
{
    uint64_t at = 0;
    while (at + 16 <= length) {
        uint64_t addr = get64(rec + at), size = get64(rec + at + 8);
        if (size > length - at - 16) return -1;
        if (write_all(fd, rec + at + 16, (size_t)size, (off_t)addr) != 0) return -1;
        at += 16 + size;
        if (kill) raise(SIGKILL);
    }
    if (at != length) return -1;
    while (ftruncate(fd, (off_t)final_size) != 0)
        if (errno != EINTR) return -1;
    return 0;
}

/* Steps 1-3 for the writes kept, leaving the file `final_size` bytes long. */
static int commit(journal_file_t *f, uint64_t final_size)
{
    uint64_t length = 0, start;
    unsigned char *rec, *p, footer[FOOTER_BYTES];
    struct stat st;
    int status;

    if (f->n_kept == 0) {
        if (fstat(f->fd, &st) != 0) return -1;
        if ((uint64_t)st.st_size == final_size) return 0;
        return ftruncate(f->fd, (off_t)final_size) == 0 ? 0 : -1;
    }
    for (size_t i = 0; i < f->n_kept; i++) length += 16 + f->kept[i].size;
    if (fstat(f->fd, &st) != 0) return -1;
    start = (uint64_t)st.st_size > final_size ? (uint64_t)st.st_size : final_size;
    for (size_t i = 0; i < f->n_kept; i++)
        if (f->kept[i].addr + f->kept[i].size > start) start = f->kept[i].addr + f->kept[i].size;
    rec = malloc(length ? length : 1);
    if (!rec) return -1;
    p = rec;
    for (size_t i = 0; i < f->n_kept; i++) {
        put64(p, f->kept[i].addr);
        put64(p + 8, f->kept[i].size);
        memcpy(p + 16, f->kept[i].bytes, f->kept[i].size);
        p += 16 + f->kept[i].size;
    }
    memcpy(footer, JOURNAL_MAGIC, 8);
    put64(footer + 8, start);
    put64(footer + 16, length);
    put64(footer + 24, final_size);
    put64(footer + 32, crc32_of(rec, length));
    status = write_all(f->fd, rec, length, (off_t)start);
    if (status == 0) status = write_all(f->fd, footer, FOOTER_BYTES, (off_t)(start + length));
    if (status == 0) status = apply_records(f->fd, rec, length, final_size, ++f->commits == f->kill_at);
    free(rec);
    if (status != 0) return -1;
    for (size_t i = 0; i < f->n_kept; i++) free(f->kept[i].bytes);
    f->n_kept = 0;
    return 0;
}

/* A journal left at the end of the file at `path` by a killed writer: applied and
 * removed. Returns 1 when one was applied, 0 when there was none (or another
 * process holds the file's flock: a writer at work), -1 when the file cannot be
 * opened for writing or the journal cannot be applied. */
int voiga_journal_recover(const char *path)
{
    unsigned char footer[FOOTER_BYTES], *rec;
    uint64_t start, length, final_size;
    struct stat st;
    int fd, status = 0;

    fd = open_regular(path, O_RDWR);
    if (fd < 0) return -1;
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        close(fd);
        return errno == EWOULDBLOCK ? 0 : -1;
    }
    if (fstat(fd, &st) != 0 || st.st_size < FOOTER_BYTES ||
        read_all(fd, footer, FOOTER_BYTES, st.st_size - FOOTER_BYTES) != 0 ||
        memcmp(footer, JOURNAL_MAGIC, 8) != 0) {
        close(fd);
        return 0;
    }
    start = get64(footer + 8);
    length = get64(footer + 16);
    final_size = get64(footer + 24);
    if (start + length + FOOTER_BYTES != (uint64_t)st.st_size || final_size > start) {
        close(fd);
        return 0; /* not a footer of ours: bytes that happen to match */
    }
    rec = malloc(length ? length : 1);
    if (!rec || read_all(fd, rec, (size_t)length, (off_t)start) != 0) {
        free(rec);
        close(fd);
        return -1;
    }
    if (crc32_of(rec, length) == get64(footer + 32))
        status = apply_records(fd, rec, length, final_size, 0) == 0 ? 1 : -1;
    free(rec);
    close(fd);
    return status;
}

static H5FD_t *j_open(const char *name, unsigned flags, hid_t fapl, haddr_t maxaddr)
{
    int oflags = O_CLOEXEC, fd;
    struct stat st;
    journal_file_t *f;
    const char *hook = getenv("VOIGA_JOURNAL_KILL");
    (void)fapl;
    (void)maxaddr;
    if (flags & H5F_ACC_RDWR) oflags |= O_RDWR; else oflags |= O_RDONLY;
    if (flags & H5F_ACC_TRUNC) oflags |= O_TRUNC;
    if (flags & H5F_ACC_CREAT) oflags |= O_CREAT;
    if (flags & H5F_ACC_EXCL) oflags |= O_EXCL;
    if ((flags & H5F_ACC_RDWR) && !(flags & (H5F_ACC_TRUNC | H5F_ACC_CREAT)) && voiga_journal_recover(name) < 0)
        return NULL;
    fd = (oflags & O_CREAT) ? open(name, oflags | O_NOFOLLOW, 0666) : open_regular(name, oflags);
    if (fd < 0) return NULL;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return NULL;
    }
    f = calloc(1, sizeof(*f));
    if (!f) {
        close(fd);
        return NULL;
    }
    f->fd = fd;
    f->eof = (haddr_t)st.st_size;
    f->device = st.st_dev;
    f->inode = st.st_ino;
    f->kill_at = hook ? atol(hook) : -1;
    return (H5FD_t *)f;
}

static herr_t j_close(H5FD_t *file)
{
    journal_file_t *f = (journal_file_t *)file;
    herr_t status = commit(f, f->eof) == 0 ? 0 : -1;
    for (size_t i = 0; i < f->n_kept; i++) free(f->kept[i].bytes);
    free(f->kept);
    if (close(f->fd) != 0) status = -1;
    free(f);
    return status;
}

static int j_cmp(const H5FD_t *a, const H5FD_t *b)
{
    const journal_file_t *x = (const journal_file_t *)a, *y = (const journal_file_t *)b;
    if (x->device != y->device) return x->device < y->device ? -1 : 1;
    if (x->inode != y->inode) return x->inode < y->inode ? -1 : 1;
    return 0;
}

static herr_t j_query(const H5FD_t *file, unsigned long *flags)
{
    (void)file;
    *flags = H5FD_FEAT_AGGREGATE_METADATA | H5FD_FEAT_ACCUMULATE_METADATA | H5FD_FEAT_DATA_SIEVE |
             H5FD_FEAT_AGGREGATE_SMALLDATA;
    return 0;
}

static haddr_t j_get_eoa(const H5FD_t *file, H5FD_mem_t type)
{
    (void)type;
    return ((const journal_file_t *)file)->eoa;
}

static herr_t j_set_eoa(H5FD_t *file, H5FD_mem_t type, haddr_t addr)
{
    (void)type;
    ((journal_file_t *)file)->eoa = addr;
    return 0;
}

static haddr_t j_get_eof(const H5FD_t *file, H5FD_mem_t type)
{
    (void)type;
    return ((const journal_file_t *)file)->eof;
}

static herr_t j_get_handle(H5FD_t *file, hid_t fapl, void **handle)
{
    (void)fapl;
    *handle = &((journal_file_t *)file)->fd;
    return 0;
}

static herr_t j_read(H5FD_t *file, H5FD_mem_t type, hid_t dxpl, haddr_t addr, size_t size, void *buf)
{
    journal_file_t *f = (journal_file_t *)file;
    (void)type;
    (void)dxpl;
    if (addr + size > f->eoa) return -1;
    if (read_all(f->fd, buf, size, (off_t)addr) != 0) return -1;
    for (size_t i = 0; i < f->n_kept; i++) { /* in order: later writes win */
        const pending_t *k = &f->kept[i];
        haddr_t lo = k->addr > addr ? k->addr : addr;
        haddr_t hi = k->addr + k->size < addr + size ? k->addr + k->size : addr + size;
        if (lo < hi) memcpy((unsigned char *)buf + (lo - addr), k->bytes + (lo - k->addr), hi - lo);
    }
    return 0;
}

static herr_t j_write(H5FD_t *file, H5FD_mem_t type, hid_t dxpl, haddr_t addr, size_t size, const void *buf)
{
    journal_file_t *f = (journal_file_t *)file;
    pending_t *k;
    (void)type;
    (void)dxpl;
    if (addr + size > f->eoa) return -1;
    for (size_t i = f->n_kept; i-- > 0;) { /* the same block written again: replace it */
        k = &f->kept[i];
        if (k->addr == addr && k->size == size) {
            memcpy(k->bytes, buf, size);
            return 0;
        }
        if (k->addr < addr + size && addr < k->addr + k->size) break; /* overlaps: keep order */
    }
    if (f->n_kept == f->cap_kept) {
        size_t cap = f->cap_kept ? 2 * f->cap_kept : 64;
        pending_t *grown = realloc(f->kept, cap * sizeof(*grown));
        if (!grown) return -1;
        f->kept = grown;
        f->cap_kept = cap;
    }
    k = &f->kept[f->n_kept];
    k->bytes = malloc(size ? size : 1);
    if (!k->bytes) return -1;
    memcpy(k->bytes, buf, size);
    k->addr = addr;
    k->size = size;
    f->n_kept++;
    if (addr + size > f->eof) f->eof = addr + size;
    return 0;
}

static herr_t j_flush(H5FD_t *file, hid_t dxpl, hbool_t closing)
{
    journal_file_t *f = (journal_file_t *)file;
    (void)dxpl;
    (void)closing;
    return commit(f, f->eof) == 0 ? 0 : -1;
}

/* HDF5 truncates before it writes the superblock, within one flush: the new size
 * is the file's from the flush (or close) that follows, in the same commit. */
static herr_t j_truncate(H5FD_t *file, hid_t dxpl, hbool_t closing)
{
    journal_file_t *f = (journal_file_t *)file;
    (void)dxpl;
    (void)closing;
    f->eof = f->eoa;
    return 0;
}

/* The driver value HDF5 1.13.2 and later ask for: one of the values 256-511 that
 * HDF5 leaves to unregistered drivers. */
#define JOURNAL_DRIVER_VALUE 479

/* The driver: what it does not name is zero (no superblock or property-list
 * extensions, HDF5's own allocation and locking). */
static const H5FD_class_t journal_class = {
#ifdef H5FD_CLASS_VERSION
    .version = H5FD_CLASS_VERSION,
    .value = (H5FD_class_value_t)JOURNAL_DRIVER_VALUE,
#endif
    .name = "voiga_journal",
    .maxaddr = MAX_ADDR,
    .fc_degree = H5F_CLOSE_WEAK,
    .open = j_open,
    .close = j_close,
    .cmp = j_cmp,
    .query = j_query,
    .get_eoa = j_get_eoa,
    .set_eoa = j_set_eoa,
    .get_eof = j_get_eof,
    .get_handle = j_get_handle,
    .read = j_read,
    .write = j_write,
    .flush = j_flush,
    .truncate = j_truncate,
    .fl_map = H5FD_FLMAP_DICHOTOMY,
};

/* Make the file access property list `fapl` use the journaled driver, with a small
 * metadata cache (64 KiB): HDF5 1.10 scans every cached entry at each flush
 * (H5C_set_slist_enabled, 16 % of an ironing m1 N2 run with the default 2 MiB cache,
 * which keeps every step's headers); a result file's writes need few entries at a
 * time. Measured: ironing m1 N2 0.89 (256 KiB) and 0.85 (64 KiB) of the default's
 * wall time. 0 on success. */
int voiga_journal_fapl(hid_t fapl)
{
    if (driver_id < 0) driver_id = H5FDregister(&journal_class);
    if (driver_id < 0) return -1;
    {
        H5AC_cache_config_t c;
        c.version = H5AC__CURR_CACHE_CONFIG_VERSION;
        if (H5Pget_mdc_config(fapl, &c) < 0) return -1;
        c.set_initial_size = 1;
        c.initial_size = 64 * 1024;
        c.min_size = 32 * 1024;
        c.max_size = 64 * 1024;
        if (H5Pset_mdc_config(fapl, &c) < 0) return -1;
    }
    return H5Pset_driver(fapl, driver_id, NULL) < 0 ? -1 : 0;
}

/* The descriptor of the open HDF5 file `file` (its driver's; -1 when there is
 * none): what a writer checks its file's name against (os.f90's names_file). */
int voiga_h5_fd(hid_t file)
{
    void *handle = NULL;
    if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || handle == NULL) return -1;
    return *(int *)handle;
}
