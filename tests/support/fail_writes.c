/* A disk that fills up, for tests (LD_PRELOAD): with QSGI_FAIL_WRITES_AFTER=N in the environment,
 * writes to regular files succeed for the first N bytes in all and then fail with ENOSPC, the way
 * a full file system answers; a write that crosses the limit writes what fits, as a real one
 * does. With QSGI_FAIL_FLOCK=1, flock() fails with ENOLCK, as on a file system that cannot lock.
 * Pipes, terminals and sockets are never affected. Only the calls a program makes through libc's
 * symbols are seen, which is how qsgi writes (write, pwrite, writev). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

static atomic_llong written;

/* How many of `size` bytes to `fd` may still be written: size when unlimited or not a file. */
static size_t allowance(int fd, size_t size) {
    const char* limit = getenv("QSGI_FAIL_WRITES_AFTER");
    struct stat status;
    if (!limit || fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) return size;
    const long long budget = atoll(limit);
    const long long before = atomic_fetch_add(&written, (long long)size);
    if (before >= budget) return 0;
    return before + (long long)size <= budget ? size : (size_t)(budget - before);
}

ssize_t write(int fd, const void* buffer, size_t size) {
    static ssize_t (*real)(int, const void*, size_t);
    if (!real) real = (ssize_t(*)(int, const void*, size_t))dlsym(RTLD_NEXT, "write");
    const size_t allowed = allowance(fd, size);
    if (size > 0 && allowed == 0) {
        errno = ENOSPC;
        return -1;
    }
    return real(fd, buffer, allowed);
}

ssize_t pwrite(int fd, const void* buffer, size_t size, off_t offset) {
    static ssize_t (*real)(int, const void*, size_t, off_t);
    if (!real) real = (ssize_t(*)(int, const void*, size_t, off_t))dlsym(RTLD_NEXT, "pwrite");
    const size_t allowed = allowance(fd, size);
    if (size > 0 && allowed == 0) {
        errno = ENOSPC;
        return -1;
    }
    return real(fd, buffer, allowed, offset);
}

ssize_t pwrite64(int fd, const void* buffer, size_t size, off_t offset) { return pwrite(fd, buffer, size, offset); }

ssize_t writev(int fd, const struct iovec* parts, int count) {
    static ssize_t (*real)(int, const struct iovec*, int);
    if (!real) real = (ssize_t(*)(int, const struct iovec*, int))dlsym(RTLD_NEXT, "writev");
    size_t size = 0;
    for (int i = 0; i < count; ++i) size += parts[i].iov_len;
    if (size > 0 && allowance(fd, size) < size) {
        errno = ENOSPC; /* simpler than a partial vector write, and as legal */
        return -1;
    }
    return real(fd, parts, count);
}

int flock(int fd, int operation) {
    static int (*real)(int, int);
    if (!real) real = (int (*)(int, int))dlsym(RTLD_NEXT, "flock");
    const char* fail = getenv("QSGI_FAIL_FLOCK");
    if (fail && *fail == '1') {
        errno = ENOLCK;
        return -1;
    }
    return real(fd, operation);
}
