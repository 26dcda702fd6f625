/* The POSIX calls Fortran cannot make on its own (signal handlers, posix_spawn, waitpid's
 * status macros, a thread): glue for ropedyn_process.f90, which is the only caller.
 *
 * - Signals: SIGINT and SIGTERM set a flag that the program polls (the run driver between
 *   integration steps, the local sweep runner). Catching nests: every catch is matched by a
 *   release, and the handlers go with the last release. With "second ends" on, a signal
 *   that arrives when one was caught already ends the process at once by that signal (a
 *   second Ctrl-C).
 * - A lock's heartbeat: a thread that touches the lock file every few seconds, so that a
 *   reader on another host can tell a live writer from one that is gone. One thread per
 *   lock (a handle each): two runs in one process (the library's, in two threads) hold
 *   two locks.
 * - Worker processes: spawned in their own process group with stdout and stderr in a log
 *   file; reaped without blocking; signalled as a group; waited for: while children are
 *   watched, SIGCHLD has a handler that does nothing and is blocked except inside
 *   ropedyn_wait_children, which sleeps until a child ends, a signal is caught or its time
 *   is up (a child that ends between a reap and the wait leaves SIGCHLD pending, and the
 *   wait returns at once).
 * - Process start times (/proc/PID/stat), to tell a live PID from a reused one.
 *
 * Only async-signal-safe calls (write, signal, raise) happen in the handler. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

static const int CAUGHT[2] = {SIGINT, SIGTERM};
static struct sigaction saved[2];
static int installed = 0;   /* catches not yet released */
static volatile sig_atomic_t received = 0;
static volatile sig_atomic_t second_ends = 0;

/* One heartbeat: the lock file, its period, the thread that touches it. */
struct heartbeat {
    int fd;
    int seconds;
    pthread_t thread;
};

static void on_signal(int sig)
{
    if (received && second_ends) {
        static const char msg[] = "\nropedyn: a second signal: ending at once\n";
        ssize_t rc = write(2, msg, sizeof msg - 1);
        (void)rc;
        signal(sig, SIG_DFL);
        raise(sig);
        return;
    }
    if (!received) received = sig;
}

/* Catch SIGINT and SIGTERM: the handler sets the flag (a signal ignored at start stays
 * ignored). Nested calls only count (each needs its release). Returns 0, or errno. */
int ropedyn_catch_signals(void)
{
    struct sigaction sa;
    int k;
    if (installed) {
        installed++;
        return 0;
    }
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    for (k = 0; k < 2; k++) {
        if (sigaction(CAUGHT[k], NULL, &saved[k]) != 0) return errno;
        if (saved[k].sa_handler == SIG_IGN) continue;
        if (sigaction(CAUGHT[k], &sa, NULL) != 0) return errno;
    }
    installed = 1;
    return 0;
}

/* on != 0: a signal caught while the flag is set already ends the process at once (by that
 * signal); 0: it only keeps the flag. */
void ropedyn_second_signal_ends(int on) { second_ends = on ? 1 : 0; }

/* Undo one ropedyn_catch_signals; the last one restores the dispositions from before the
 * first and switches "second ends" off. The flag stays. */
void ropedyn_release_signals(void)
{
    int k;
    if (installed > 1) {
        installed--;
        return;
    }
    if (installed) {
        for (k = 0; k < 2; k++) sigaction(CAUGHT[k], &saved[k], NULL);
        installed = 0;
    }
    second_ends = 0;
}

/* The first signal caught (its number), or 0. */
int ropedyn_signal_received(void) { return (int)received; }

static void *beat(void *arg)
{
    struct heartbeat *h = arg;
    for (;;) {
        sleep((unsigned)h->seconds);   /* a cancellation point */
        futimens(h->fd, NULL);
    }
    return NULL;
}

/* Touch `path` now and every `seconds` s from a thread (which blocks every signal) until
 * ropedyn_stop_heartbeat of the handle put in *handle. Returns 0, or errno. */
int ropedyn_start_heartbeat(const char *path, int seconds, void **handle)
{
    sigset_t all, old;
    int rc;
    struct heartbeat *h = malloc(sizeof *h);
    *handle = NULL;
    if (!h) return ENOMEM;
    h->fd = open(path, O_WRONLY | O_CLOEXEC);
    if (h->fd < 0) {
        rc = errno;
        free(h);
        return rc;
    }
    futimens(h->fd, NULL);
    h->seconds = seconds > 0 ? seconds : 1;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    rc = pthread_create(&h->thread, NULL, beat, h);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (rc != 0) {
        close(h->fd);
        free(h);
        return rc;
    }
    *handle = h;
    return 0;
}

/* Stop the heartbeat `handle` (NULL: none) and free it. */
void ropedyn_stop_heartbeat(void *handle)
{
    struct heartbeat *h = handle;
    if (!h) return;
    pthread_cancel(h->thread);
    pthread_join(h->thread, NULL);
    close(h->fd);
    free(h);
}

/* Start `nargs` NUL-separated arguments (the first is the program, looked up in PATH
 * when it holds no '/') in a new process group, stdin from /dev/null, stdout and stderr
 * to `log` (appended to: a log is never cut, neither the one of an earlier run of the case nor
 * the one another runner's worker is writing), SIGINT and SIGTERM at their default action. Returns 0 and the
 * child's pid, or errno. */
int ropedyn_spawn(const char *args, int nargs, const char *log, int *pid)
{
    posix_spawn_file_actions_t actions;
    posix_spawnattr_t attr;
    sigset_t defaults, none;
    char **argv;
    const char *p = args;
    pid_t child;
    int k, rc;

    argv = calloc((size_t)nargs + 1, sizeof *argv);
    if (!argv) return ENOMEM;
    for (k = 0; k < nargs; k++) {
        argv[k] = (char *)p;
        p += strlen(p) + 1;
    }
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, log, O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawnattr_init(&attr);
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    sigemptyset(&none);
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF |
                                        POSIX_SPAWN_SETSIGMASK);
    rc = posix_spawnp(&child, argv[0], &actions, &attr, argv, environ);
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&actions);
    free(argv);
    if (rc == 0) *pid = (int)child;
    return rc;
}

/* 1 when child `pid` has ended (`code`: its exit status, or 128 + the signal that ended
 * it), 0 while it runs, -1 on error (errno in `code`). Does not block. */
int ropedyn_reap(int pid, int *code)
{
    int status;
    pid_t rc = waitpid((pid_t)pid, &status, WNOHANG);
    if (rc == 0) return 0;
    if (rc < 0) {
        *code = errno;
        return -1;
    }
    *code = WIFEXITED(status) ? WEXITSTATUS(status)
                              : (WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 255);
    return 1;
}

static int watching = 0;
static struct sigaction saved_chld;
static sigset_t saved_mask;

static void on_child(int sig) { (void)sig; }

/* Watch for ended children (see the header): SIGCHLD gets a handler that does nothing and
 * is blocked outside ropedyn_wait_children. Returns 0, or errno. */
int ropedyn_watch_children(void)
{
    struct sigaction sa;
    sigset_t chld;
    if (watching) return 0;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_child;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART | SA_NOCLDSTOP;
    sigemptyset(&chld);
    sigaddset(&chld, SIGCHLD);
    if (pthread_sigmask(SIG_BLOCK, &chld, &saved_mask) != 0) return EINVAL;
    if (sigaction(SIGCHLD, &sa, &saved_chld) != 0) {
        int rc = errno;
        pthread_sigmask(SIG_SETMASK, &saved_mask, NULL);
        return rc;
    }
    watching = 1;
    return 0;
}

/* Undo ropedyn_watch_children: SIGCHLD's handler and this thread's mask as they were. */
void ropedyn_unwatch_children(void)
{
    if (!watching) return;
    sigaction(SIGCHLD, &saved_chld, NULL);
    pthread_sigmask(SIG_SETMASK, &saved_mask, NULL);
    watching = 0;
}

/* Sleep until a child ends or a signal is caught (1), or `microseconds` pass (0). Without
 * ropedyn_watch_children only a caught signal ends the sleep early. */
int ropedyn_wait_children(long microseconds)
{
    struct timespec ts;
    sigset_t during;
    ts.tv_sec = microseconds / 1000000;
    ts.tv_nsec = (microseconds % 1000000) * 1000;
    pthread_sigmask(SIG_BLOCK, NULL, &during);
    sigdelset(&during, SIGCHLD);
    return ppoll(NULL, 0, &ts, &during) < 0 && errno == EINTR ? 1 : 0;
}

/* Send `sig` to the process group `pgid`. Returns 0, or errno. */
int ropedyn_signal_group(int pgid, int sig)
{
    return killpg((pid_t)pgid, sig) == 0 ? 0 : errno;
}

/* The start time of process `pid` (clock ticks after boot, /proc/PID/stat field 22; 0 for
 * this process is its own pid), 0 when the process exists but /proc cannot tell, -1 when
 * there is no such process. */
long long ropedyn_process_start(int pid)
{
    char path[64], buf[1024];
    char *p;
    unsigned long long ticks;
    ssize_t n;
    int fd, field;

    if (pid == 0) pid = (int)getpid();
    snprintf(path, sizeof path, "/proc/%d/stat", pid);
    fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        if (kill((pid_t)pid, 0) == 0 || errno == EPERM) return 0;
        return -1;
    }
    n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n <= 0) return 0;
    buf[n] = '\0';
    /* the command name (field 2) is in parentheses and may hold blanks */
    p = strrchr(buf, ')');
    if (!p) return 0;
    /* field 3, the state: a zombie (Z) or a dead process (X) has ended; only its parent
     * has not reaped it yet */
    if (p[1] == ' ' && (p[2] == 'Z' || p[2] == 'X')) return -1;
    for (field = 2; field < 22 && p; field++) p = strchr(p + 1, ' ');
    if (!p || sscanf(p + 1, "%llu", &ticks) != 1) return 0;
    return (long long)ticks;
}

/* The modification time of `path` (s since 1970), or -1 when it does not exist. */
long long ropedyn_file_mtime(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return -1;
    return (long long)st.st_mtime;
}

/* The time now, s since 1970. */
long long ropedyn_unix_time(void) { return (long long)time(NULL); }
