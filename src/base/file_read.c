/* file_read.c: opening a file to read without hanging on a named pipe
 * (file_read.h). */
#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include "base/file_read.h"

int pd_file_open_read(const char *path)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return -1;
    int flags = fcntl(fd, F_GETFL);
    if (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) < 0) {
        int err = errno;
        close(fd);
        errno = err;
        return -1;
    }
    return fd;
}

FILE *pd_file_fopen_read(const char *path)
{
    int fd = pd_file_open_read(path);
    if (fd < 0)
        return NULL;
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        int err = errno;
        close(fd);
        errno = err;
    }
    return f;
}

pd_status pd_file_check_fifo(int fd, size_t nread, const char *path, pd_diag *diag)
{
    struct stat sb;
    if (nread == 0 && fstat(fd, &sb) == 0 && S_ISFIFO(sb.st_mode))
        return pd_fail(diag, PD_ERR_IO, "%s: a named pipe that gave nothing to read (no "
                       "program was writing to it)", path);
    return PD_OK;
}
