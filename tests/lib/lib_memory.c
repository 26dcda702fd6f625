/* Memory of the C interface (include/ropedyn.h), for tests/e2e/test_library_memory.py and
 * scripts/bench_library:
 *
 *   lib_memory once          every kind of call once on a small scene, the failing ones
 *                            too (a bad scene, a bad setting, a call out of order, a
 *                            failed integration), under valgrind: nothing leaks, no
 *                            invalid access
 *   lib_memory cycles N E    N create / init / advance / destroy cycles of a small scene
 *                            from text; prints `cycle rss_kib` (VmRSS) after the first
 *                            cycle and every E cycles
 *
 * Exit status 0, or 1 when a call did not answer as it should. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ropedyn.h"

static const char *SMALL = "&model\n kind = 'rfem', elements = 4\n/\n"
                           "&solver\n t_end = 0.01, output_interval = 0.005\n/\n";

static int bad = 0;

static void expect(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "lib_memory: %s\n", what);
        bad = 1;
    }
}

static long rss_kib(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long kib = -1;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmRSS:", 6) == 0)
            kib = strtol(line + 6, NULL, 10);
    if (f)
        fclose(f);
    return kib;
}

static int once(void)
{
    ropedyn_t *sim = NULL;
    /* failures: a bad scene, a bad setting, a call before init */
    expect(ropedyn_create_from_text("&model\n elements = 1\n/\n", "bad", &sim) == 2
               && strstr(ropedyn_last_error(sim), "elements") != NULL, "bad scene");
    ropedyn_destroy(sim);
    expect(ropedyn_create_from_text(SMALL, "small", &sim) == 0, "create");
    expect(ropedyn_set(sim, "solver.rtol=-1") == 2, "bad set");
    expect(ropedyn_advance(sim, 0.01) == 2, "advance before init");
    expect(ropedyn_set(sim, "supports.top_motion=coupled\nmodel.elements=3") == 0, "set");
    const char *text = NULL;
    expect(ropedyn_scene_text(sim, &text) == 0 && strstr(text, "coupled") != NULL, "text");
    expect(ropedyn_init(sim, 0) == 0, "init");
    /* a coupled simulation: every read, save / restore */
    double p[2] = {0.0, 0.001}, v[2] = {0.0, 0.1}, f[2], xy[12], axial[4], e[6], y[64];
    int n, size;
    expect(ropedyn_size(sim, &n, &size) == 0 && n == 3 && size <= 64, "size");
    expect(ropedyn_set_support(sim, ROPEDYN_TOP, p, v) == 0, "set_support");
    expect(ropedyn_advance(sim, 0.01) == 0, "advance");
    ropedyn_snapshot_t *snap = NULL;
    expect(ropedyn_save(sim, &snap) == 0, "save");
    expect(ropedyn_advance(sim, 0.02) == 0, "advance");
    expect(ropedyn_restore(sim, snap) == 0, "restore");
    ropedyn_snapshot_destroy(snap);
    expect(ropedyn_points(sim, xy, 6) == 0 && ropedyn_forces(sim, axial, NULL, NULL, 4) == 0
               && ropedyn_reaction(sim, ROPEDYN_TOP, f) == 0
               && ropedyn_support_position(sim, ROPEDYN_BOTTOM, f) == 0
               && ropedyn_energy(sim, e) == 0 && ropedyn_get_state(sim, y, size) == 0
               && ropedyn_set_state(sim, y, size) == 0, "reads");
    expect(ropedyn_advance(sim, 0.005) == 2, "advance backwards");
    /* the whole run into memory */
    const void *image = NULL;
    size_t bytes = 0;
    expect(ropedyn_run(sim, NULL, &image, &bytes) == 0 && bytes > 0, "run into memory");
    ropedyn_destroy(sim);
    /* a failed integration */
    expect(ropedyn_create_from_text(SMALL, "fault", &sim) == 0
               && ropedyn_set(sim, "effects.fault_nan_after=0.003") == 0
               && ropedyn_init(sim, 0) == 0, "fault scene");
    expect(ropedyn_advance(sim, 0.01) == 3, "failed advance");
    ropedyn_destroy(sim);
    return bad;
}

static int cycles(long count, long every)
{
    for (long k = 1; k <= count; k++) {
        ropedyn_t *sim = NULL;
        if (ropedyn_create_from_text(SMALL, "small", &sim) != 0 || ropedyn_init(sim, 0) != 0
            || ropedyn_advance(sim, 0.01) != 0) {
            fprintf(stderr, "lib_memory: %s\n", ropedyn_last_error(sim));
            return 1;
        }
        ropedyn_destroy(sim);
        if (k == 1 || k % every == 0)
            printf("%ld %ld\n", k, rss_kib());
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "once") == 0)
        return once();
    if (argc == 4 && strcmp(argv[1], "cycles") == 0)
        return cycles(atol(argv[2]), atol(argv[3]));
    fprintf(stderr, "usage: lib_memory once | lib_memory cycles N EVERY\n");
    return 2;
}
