/* The C interface (include/ropedyn.h) from C: statuses and messages of bad scenes and bad
 * calls (no crash on NULL), a simulation's time and sizes, save/restore giving the same
 * bits, two instances (interleaved, and in two threads) giving the same bits as one
 * alone, four threads creating, reading and starting simulations at once, the run into
 * memory, and a coupled support. Argument: the source tree. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ropedyn.h"

static int passed = 0, failed = 0;
static char scene_path[4096];

static void check(int ok, const char *label)
{
    printf("%s  %s\n", ok ? "PASS" : "FAIL", label);
    if (ok) passed++;
    else failed++;
}

/* The paper's rope with n = 8 (and a coupled top with `coupled`), initialized. */
static ropedyn_t *paper(int coupled)
{
    ropedyn_t *sim = NULL;
    if (ropedyn_create_from_file(scene_path, &sim) != ROPEDYN_OK ||
        ropedyn_set(sim, "model.elements=8") != ROPEDYN_OK ||
        (coupled && ropedyn_set(sim, "supports.top_motion=coupled") != ROPEDYN_OK) ||
        ropedyn_init(sim, 0) != ROPEDYN_OK) {
        printf("setup failed: %s\n", ropedyn_last_error(sim));
        exit(1);
    }
    return sim;
}

/* Advance `sim` in steps of dt to t_end; its state into y (size n). */
static void drive(ropedyn_t *sim, double dt, double t_end, double *y, int n)
{
    for (int k = 1; k * dt <= t_end + 1e-12; k++) ropedyn_advance(sim, k * dt);
    ropedyn_get_state(sim, y, n);
}

struct job {
    double y[64];
    int n;
};

static void *thread_run(void *arg)
{
    struct job *job = arg;
    ropedyn_t *sim = paper(0);
    drive(sim, 0.01, 1.0, job->y, job->n);
    ropedyn_destroy(sim);
    return NULL;
}

static void bad_calls(void)
{
    ropedyn_t *sim = NULL;
    int status = ropedyn_create_from_text("&model elements = 1 /", "bad.nml", &sim);
    check(status == ROPEDYN_ERROR_INPUT, "a bad scene: status 2");
    check(strstr(ropedyn_last_error(sim), "bad.nml: &model: elements = 1") != NULL,
          "a bad scene: the message names the scene, group, key and value");
    ropedyn_destroy(sim);
    /* a scene that could not be read leaves no scene to show, run or simulate: before,
       init simulated the defaults (an unknown key ignored, a length of -1 m kept) */
    const char *unread[] = {"&model kind = 'rfem', elements = 4, bogus = 1 /",
                            "&model kind = 'rfem', elements = 4 /\n&rope length = -1 /"};
    for (int k = 0; k < 2; k++) {
        const char *text = NULL;
        const void *image = NULL;
        size_t bytes = 0;
        sim = NULL;
        status = ropedyn_create_from_text(unread[k], "unread.nml", &sim);
        char message[512];
        snprintf(message, sizeof message, "%s", ropedyn_last_error(sim));
        int same = status == ROPEDYN_ERROR_INPUT;
        same = same && ropedyn_scene_text(sim, &text) == status && text == NULL;
        same = same && ropedyn_warnings(sim, &text) == status;
        same = same && ropedyn_set(sim, "model.elements=6") == status;
        same = same && ropedyn_run(sim, NULL, &image, &bytes) == status && image == NULL;
        same = same && ropedyn_init(sim, 0) == status;
        same = same && strcmp(ropedyn_last_error(sim), message) == 0;
        same = same && ropedyn_advance(sim, 0.01) == status;
        check(same && strstr(message, "unread.nml: ") == message,
              k == 0 ? "a scene with an unknown key: every later call returns its error"
                     : "a scene with a bad value: every later call returns its error");
        ropedyn_destroy(sim);
    }
    sim = NULL;
    check(ropedyn_create_from_text(NULL, "x", &sim) == ROPEDYN_ERROR_INPUT &&
              ropedyn_init(sim, 0) == ROPEDYN_ERROR_INPUT &&
              strstr(ropedyn_last_error(sim), "text is NULL") != NULL,
          "NULL text: no scene to simulate");
    ropedyn_destroy(sim);
    status = ropedyn_create_from_file("/nonexistent/scene.nml", &sim);
    check(status == ROPEDYN_ERROR_INPUT && strlen(ropedyn_last_error(sim)) > 0,
          "a missing file: status 2 and a message");
    ropedyn_destroy(sim);
    check(ropedyn_advance(NULL, 1.0) == ROPEDYN_ERROR_INPUT, "NULL instance: status 2");
    check(ropedyn_last_error(NULL) == NULL, "NULL instance: no message");
    ropedyn_destroy(NULL);
    check(ropedyn_create_from_file(NULL, &sim) == ROPEDYN_ERROR_INPUT, "NULL path: status 2");
    ropedyn_destroy(sim);
    check(ropedyn_create_from_file(scene_path, NULL) == ROPEDYN_ERROR_INPUT &&
              ropedyn_create_from_text("&model elements = 4 /", "x", NULL) == ROPEDYN_ERROR_INPUT,
          "NULL for the instance: status 2 (before: 0, and nothing made)");

    sim = NULL;
    ropedyn_create_from_file(scene_path, &sim);
    check(ropedyn_advance(sim, 0.1) == ROPEDYN_ERROR_INPUT &&
              strstr(ropedyn_last_error(sim), "init") != NULL,
          "advance before init: status 2, says init");
    check(ropedyn_set(sim, "model.nosuchkey=3") == ROPEDYN_ERROR_INPUT &&
              strstr(ropedyn_last_error(sim), "unknown key") != NULL,
          "set of an unknown key: status 2");
    check(ropedyn_set(sim, "model.elements=8") == ROPEDYN_OK &&
              strcmp(ropedyn_last_error(sim), "") == 0,
          "a good set after a bad one: OK, no message");
    ropedyn_init(sim, 0);
    double f[2], p[2] = {0.0, 0.0}, v[2] = {0.0, 0.0}, y[64];
    check(ropedyn_set_support(sim, ROPEDYN_TOP, p, v) == ROPEDYN_ERROR_INPUT &&
              strstr(ropedyn_last_error(sim), "top_motion = 'coupled'") != NULL,
          "set_support of a fixed support: status 2, says how to couple it");
    /* a NULL where a result goes or a value comes from: status 2 and a message, no crash
       (before, each of these was a segmentation fault) */
    int n = 0, size = 0, nulls = 0;
    nulls += ropedyn_time(sim, NULL) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_size(sim, &n, NULL) == ROPEDYN_ERROR_INPUT && n == 0;
    nulls += ropedyn_size(sim, NULL, &size) == ROPEDYN_ERROR_INPUT && size == 0;
    nulls += ropedyn_get_state(sim, NULL, 0) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_set_state(sim, NULL, 0) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_points(sim, NULL, 16) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_reaction(sim, ROPEDYN_TOP, NULL) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_support_position(sim, ROPEDYN_TOP, NULL) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_energy(sim, NULL) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_set_support(sim, ROPEDYN_TOP, NULL, v) == ROPEDYN_ERROR_INPUT;
    nulls += ropedyn_set_support(sim, ROPEDYN_TOP, p, NULL) == ROPEDYN_ERROR_INPUT &&
             strstr(ropedyn_last_error(sim), "is NULL") != NULL;
    check(nulls == 11, "NULL arrays and results: status 2 and a message, no crash");
    check(ropedyn_reaction(sim, 7, f) == ROPEDYN_ERROR_INPUT, "reaction of support 7: 2");
    check(ropedyn_get_state(sim, y, 3) == ROPEDYN_ERROR_INPUT, "get_state of a wrong size");
    ropedyn_advance(sim, 0.2);
    check(ropedyn_advance(sim, 0.1) == ROPEDYN_ERROR_INPUT, "advance backwards: status 2");
    double t = 0.0;
    ropedyn_time(sim, &t);
    check(t == 0.2, "after a refused call the simulation is where it was");
    check(ropedyn_advance(sim, NAN) == ROPEDYN_ERROR_INPUT, "advance to NaN: status 2");
    ropedyn_destroy(sim);
}

static void simulation(void)
{
    ropedyn_t *sim = paper(0);
    int n = 0, size = 0;
    ropedyn_size(sim, &n, &size);
    check(n == 8 && size > 0 && size <= 64, "sizes: 8 elements");
    double y1[64], y2[64], ya[64], yb[64], t = -1.0;
    ropedyn_advance(sim, 0.25);
    ropedyn_time(sim, &t);
    check(t == 0.25, "time reached");
    double xy[32], axial[9], e[6], f[2];
    check(ropedyn_points(sim, xy, 16) == ROPEDYN_OK && fabs(xy[0]) + fabs(xy[1]) < 0.2,
          "points: the first near the top anchor");
    check(ropedyn_forces(sim, axial, NULL, NULL, 9) == ROPEDYN_OK && axial[0] > 0.0,
          "forces: tension at the top");
    check(ropedyn_reaction(sim, ROPEDYN_TOP, f) == ROPEDYN_OK && f[0] < 0.0,
          "reaction: the top pulls up (x down)");
    check(ropedyn_energy(sim, e) == ROPEDYN_OK && e[5] < 0.0, "energies");

    /* save, go on, restore, go on again: the same bits */
    ropedyn_snapshot_t *snap = NULL;
    check(ropedyn_save(sim, &snap) == ROPEDYN_OK && snap != NULL, "save");
    drive(sim, 0.05, 0.5, ya, size);
    check(ropedyn_restore(sim, snap) == ROPEDYN_OK, "restore");
    ropedyn_time(sim, &t);
    check(t == 0.25, "restore: back at the saved time");
    drive(sim, 0.05, 0.5, yb, size);
    check(memcmp(ya, yb, sizeof(double) * size) == 0, "after restore: the same bits");
    ropedyn_snapshot_destroy(snap);
    ropedyn_destroy(sim);

    /* two instances interleaved, against one alone */
    ropedyn_t *a = paper(0), *b = paper(0), *alone = paper(0);
    for (int k = 1; k <= 100; k++) {
        ropedyn_advance(a, k * 0.01);
        ropedyn_advance(b, k * 0.01);
    }
    ropedyn_get_state(a, y1, size);
    ropedyn_get_state(b, y2, size);
    drive(alone, 0.01, 1.0, ya, size);
    check(memcmp(y1, ya, sizeof(double) * size) == 0 &&
              memcmp(y2, ya, sizeof(double) * size) == 0,
          "two instances interleaved: the bits of one alone");
    ropedyn_destroy(a);
    ropedyn_destroy(b);
    ropedyn_destroy(alone);

    /* two threads */
    pthread_t th[2];
    struct job jobs[2] = {{.n = size}, {.n = size}};
    for (int k = 0; k < 2; k++) pthread_create(&th[k], NULL, thread_run, &jobs[k]);
    for (int k = 0; k < 2; k++) pthread_join(th[k], NULL);
    check(memcmp(jobs[0].y, ya, sizeof(double) * size) == 0 &&
              memcmp(jobs[1].y, ya, sizeof(double) * size) == 0,
          "two instances in two threads: the bits of one alone");
}

/* One thread's share of `threads_at_once`: create from text, set, read the scene and its
 * warnings, init and advance, `rounds` times; the calls that failed, or whose scene text
 * lost the setting, counted in *bad. */
static void *busy(void *arg)
{
    int *bad = arg;
    const char *scene = "&model kind = 'rfem', elements = 4 /\n&solver t_end = 1.0 /\n";
    for (int k = 0; k < 150; k++) {
        ropedyn_t *sim = NULL;
        const char *text = NULL;
        int status = ropedyn_create_from_text(scene, "busy", &sim);
        if (status == ROPEDYN_OK) status = ropedyn_set(sim, "model.elements=6");
        if (status == ROPEDYN_OK) status = ropedyn_scene_text(sim, &text);
        if (status == ROPEDYN_OK && strstr(text, "elements = 6") == NULL) status = -1;
        if (status == ROPEDYN_OK) status = ropedyn_warnings(sim, &text);
        if (status == ROPEDYN_OK) status = ropedyn_init(sim, 0);
        if (status == ROPEDYN_OK) status = ropedyn_advance(sim, 0.002);
        if (status != ROPEDYN_OK) ++*bad;
        ropedyn_destroy(sim);
    }
    return NULL;
}

/* Four threads calling at once, 600 simulations in all. Without the library's lock
 * (src/lib/ropedyn_serial.c) the Fortran code's static lengths of character results are
 * shared between threads: garbled scene names and messages, and a corrupted heap (the
 * process aborted in six runs of six). */
static void threads_at_once(void)
{
    pthread_t th[4];
    int bad[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; k++) pthread_create(&th[k], NULL, busy, &bad[k]);
    for (int k = 0; k < 4; k++) pthread_join(th[k], NULL);
    check(bad[0] + bad[1] + bad[2] + bad[3] == 0,
          "four threads creating, setting, reading and starting simulations: every call "
          "succeeds");
}

static void whole_run(void)
{
    ropedyn_t *sim = NULL;
    const void *image = NULL;
    size_t bytes = 0;
    ropedyn_create_from_file(scene_path, &sim);
    ropedyn_set(sim, "model.elements=8");
    ropedyn_set(sim, "solver.t_end=0.5");
    check(ropedyn_run(sim, NULL, &image, &bytes) == ROPEDYN_OK, "run into memory");
    check(image != NULL && bytes > 8 && memcmp(image, "\211HDF\r\n\032\n", 8) == 0,
          "run into memory: an HDF5 file image");
    ropedyn_destroy(sim);
}

static void coupled(void)
{
    ropedyn_t *sim = paper(1);
    double p[2], v[2], anchor[2], f[2];
    int ok = 1;
    for (int k = 1; k <= 200; k++) {
        double t = k * 1e-3, w = 2.0 * M_PI;
        p[0] = 0.0;
        p[1] = 0.02 * sin(w * t);
        v[0] = 0.0;
        v[1] = 0.02 * w * cos(w * t);
        ok = ok && ropedyn_set_support(sim, ROPEDYN_TOP, p, v) == ROPEDYN_OK;
        ok = ok && ropedyn_advance(sim, t) == ROPEDYN_OK;
        ropedyn_support_position(sim, ROPEDYN_TOP, anchor);
        ok = ok && anchor[0] == p[0] && fabs(anchor[1] - p[1]) < 1e-15;
    }
    check(ok, "coupled top: at the prescribed position after each advance");
    check(ropedyn_reaction(sim, ROPEDYN_TOP, f) == ROPEDYN_OK && isfinite(f[1]),
          "coupled top: a finite reaction");
    ropedyn_destroy(sim);
}

int main(int argc, char **argv)
{
    snprintf(scene_path, sizeof scene_path, "%s/input/paper.nml", argc > 1 ? argv[1] : ".");
    check(strlen(ropedyn_version()) > 0, "version");
    bad_calls();
    simulation();
    threads_at_once();
    whole_run();
    coupled();
    printf("capi: %d passed, %d failed\n", passed, failed);
    return failed > 0 || passed == 0;
}
