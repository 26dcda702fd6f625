/* Benchmark (not a test) of libropedyn's C interface (include/ropedyn.h), used by
 * scripts/bench_library (docs/performance/library.md).
 *
 *   bench_library overhead SCENE.nml T DT REPEAT
 *       The cost of one ropedyn_advance call on top of the integration: the scene (not
 *       coupled: the integrator's steps do not depend on where advance stops, after a
 *       first call to DT that both make) integrated on to T in one call, and in calls
 *       every DT; (CPU of the second - CPU of the first) /
 *       calls. Each the least of REPEAT runs. Also the CPU of a call that has nothing to
 *       integrate (advance to the time reached). Prints
 *       `calls one_call_s many_calls_s overhead_us empty_call_ns max_state_difference`.
 *
 * CPU time is the process's (CLOCK_PROCESS_CPUTIME_ID). The memory over many cycles:
 * tests/lib/lib_memory.c. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <math.h>

#include "ropedyn.h"

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void check(ropedyn_t *sim, int status, const char *what)
{
    if (status != ROPEDYN_OK) {
        fprintf(stderr, "bench_library: %s: %s\n", what, ropedyn_last_error(sim));
        exit(1);
    }
}

static ropedyn_t *start(const char *scene)
{
    ropedyn_t *sim = NULL;
    check(sim, ropedyn_create_from_file(scene, &sim), "create");
    check(sim, ropedyn_init(sim, 0), "init");
    return sim;
}

/* CPU seconds to integrate from |dt| to t_end in calls every dt (dt < 0: one call); the
 * end state into y. */
static double integrate(const char *scene, double t_end, double dt, double *y, int size)
{
    ropedyn_t *sim = start(scene);
    double step = dt > 0 ? dt : -dt;
    /* the first call alike in both (the first step is bounded by the first span) */
    check(sim, ropedyn_advance(sim, step), "advance");
    double c = cpu_now();
    if (dt <= 0) {
        check(sim, ropedyn_advance(sim, t_end), "advance");
    } else {
        long calls = (long)(t_end / dt + 0.5);
        for (long k = 2; k <= calls; k++)
            check(sim, ropedyn_advance(sim, k == calls ? t_end : k * dt), "advance");
    }
    c = cpu_now() - c;
    check(sim, ropedyn_get_state(sim, y, size), "get_state");
    ropedyn_destroy(sim);
    return c;
}

static int overhead(const char *scene, double t_end, double dt, int repeat)
{
    ropedyn_t *sim = start(scene);
    int n, size;
    check(sim, ropedyn_size(sim, &n, &size), "size");
    double *y1 = malloc(sizeof(double) * size), *y2 = malloc(sizeof(double) * size);
    double one = 1e300, many = 1e300;
    for (int r = 0; r < repeat; r++) {
        double a = integrate(scene, t_end, -dt, y1, size);
        double b = integrate(scene, t_end, dt, y2, size);
        one = a < one ? a : one;
        many = b < many ? b : many;
    }
    long calls = (long)(t_end / dt + 0.5);
    /* a call with nothing to integrate: the interface's own cost */
    check(sim, ropedyn_advance(sim, 0.01), "advance");
    long empty = 2000000;
    double best = 1e300;
    for (int r = 0; r < repeat; r++) {
        double c = cpu_now();
        for (long k = 0; k < empty; k++)
            ropedyn_advance(sim, 0.01);
        c = cpu_now() - c;
        best = c < best ? c : best;
    }
    ropedyn_destroy(sim);
    double diff = 0;
    for (int i = 0; i < size; i++)
        diff = fabs(y1[i] - y2[i]) > diff ? fabs(y1[i] - y2[i]) : diff;
    printf("%ld %.6f %.6f %.4f %.2f %.3g\n", calls - 1, one, many, 1e6 * (many - one) / (calls - 1),
           1e9 * best / empty, diff);
    free(y1);
    free(y2);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 6 && strcmp(argv[1], "overhead") == 0)
        return overhead(argv[2], atof(argv[3]), atof(argv[4]), atoi(argv[5]));
    fprintf(stderr, "usage: bench_library overhead SCENE.nml T DT REPEAT\n");
    return 2;
}
