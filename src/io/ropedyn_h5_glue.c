/* Glue for ropedyn_h5.f90, which is the only caller: why an HDF5 call failed, the
 * library's end at the exit of the process, string attributes of variable length
 * (which the Fortran interface of HDF5 1.10 does not read), and files in memory (the core
 * driver without a backing store) with their image.
 *
 * Why a call failed, in the system's words (h5_reason). The Fortran interface of HDF5
 * returns only a negative code;
 * the library's error stack (silenced by ropedyn_h5, not cleared until the next HDF5 call)
 * holds what happened, and for a failed system call its errno text, e.g.
 *
 *     file write failed: ..., errno = 28, error message = 'No space left on device', ...
 *     unable to lock file, errno = 11, error message = 'Resource temporarily unavailable'
 *
 * The reason is that text when a frame has one, else the innermost frame's description. */
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <hdf5.h>

struct reason {
    char system[256];   /* the first "error message = '...'" found */
    char inner[256];    /* the innermost frame's description */
    int errnum;         /* its "errno = N", or 0 */
};

static herr_t visit(unsigned n, const H5E_error2_t *frame, void *data)
{
    struct reason *r = data;
    const char *desc = frame->desc ? frame->desc : "";
    const char *m, *e;
    if (n == 0) snprintf(r->inner, sizeof r->inner, "%s", desc);
    if (r->system[0]) return 0;
    m = strstr(desc, "error message = '");
    if (m) {
        m += strlen("error message = '");
        e = strchr(m, '\'');
        snprintf(r->system, sizeof r->system, "%.*s", (int)(e ? e - m : (long)strlen(m)), m);
        e = strstr(desc, "errno = ");
        if (e) sscanf(e + strlen("errno = "), "%d", &r->errnum);
    }
    return 0;
}

/* The reason of the last failure on HDF5's default error stack in `buf` (`size` bytes,
 * NUL-terminated; "" when the stack is empty). Returns the errno of a failed system call
 * found on the stack, or 0. */
int ropedyn_h5_reason(char *buf, int size)
{
    struct reason r;
    memset(&r, 0, sizeof r);
    if (size < 1) return 0;
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, visit, &r);
    snprintf(buf, (size_t)size, "%s", r.system[0] ? r.system : r.inner);
    return r.errnum;
}

/* The library's end at exit. HDF5 closes what is still open when the process exits (its
 * own atexit handler). After a file failed to close (its last flush failed: a full disk),
 * that file is left half closed, and the library's handler crashed in H5F__close_cb
 * (SIGSEGV after the error message). ropedyn_h5_prepare, called before the library is
 * first opened, replaces that handler with one that ends the library only when no close
 * has failed; ropedyn_h5_close_failed says one has. Without it nothing changes. */
static int close_failed = 0;

static void end_library(void)
{
    if (!close_failed) H5close();
}

static void prepare_once(void)
{
    if (H5dont_atexit() >= 0) atexit(end_library);
    /* A file-size limit (ulimit -f) then makes a write fail with EFBIG, an I/O error the
     * writer handles (the file closed, marked failed), instead of ending the process by
     * SIGXFSZ with its file left 'running'. */
    signal(SIGXFSZ, SIG_IGN);
}

/* Once per process (the library's runs in two threads may both be first). */
void ropedyn_h5_prepare(void)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, prepare_once);
}

void ropedyn_h5_close_failed(void) { close_failed = 1; }

/* The scalar variable-length string attribute `name` of the object `loc` (as h5py writes
 * strings) in `buf` (`size` bytes, NUL-terminated, clipped). Returns the length of the
 * whole string (call again with a larger buffer when it did not fit), -2 when the
 * attribute is not a variable-length string, -1 when it cannot be read. */
int ropedyn_h5_vlen_attribute(hid_t loc, const char *name, char *buf, int size)
{
    hid_t attr, type, mem;
    char *value = NULL;
    int rc = -1;
    if (size >= 1) buf[0] = '\0';
    attr = H5Aopen(loc, name, H5P_DEFAULT);
    if (attr < 0) return -1;
    type = H5Aget_type(attr);
    if (type >= 0 && (H5Tget_class(type) != H5T_STRING || H5Tis_variable_str(type) <= 0)) {
        rc = -2;
    } else if (type >= 0) {
        mem = H5Tcopy(H5T_C_S1);
        H5Tset_size(mem, H5T_VARIABLE);
        H5Tset_cset(mem, H5Tget_cset(type));   /* h5py's are UTF-8: no conversion */
        if (H5Aread(attr, mem, &value) >= 0) {
            rc = value ? (int)strlen(value) : 0;
            if (size >= 1) snprintf(buf, (size_t)size, "%s", value ? value : "");
            H5free_memory(value);
        }
        H5Tclose(mem);
    }
    if (type >= 0) H5Tclose(type);
    H5Aclose(attr);
    return rc;
}

/* Create the file `name` in memory only (the core driver, grown 1 MiB at a time, nothing
 * written to disk; `name` must differ from that of every other file open in the process).
 * Returns its id, or a negative value. */
hid_t ropedyn_h5_create_memory(const char *name)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS), file = -1;
    if (fapl < 0) return -1;
    if (H5Pset_fapl_core(fapl, (size_t)1 << 20, 0) >= 0)
        file = H5Fcreate(name, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    H5Pclose(fapl);
    return file;
}

/* The image of the open file `file` (what would be on disk) into `buf` of `size` bytes
 * (NULL: only the size). Returns the image's size, or -1. */
long long ropedyn_h5_image(hid_t file, void *buf, long long size)
{
    H5Fflush(file, H5F_SCOPE_GLOBAL);
    return (long long)H5Fget_file_image(file, buf, buf ? (size_t)size : 0);
}
