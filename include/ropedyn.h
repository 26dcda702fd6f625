/* ropedyn.h: the C interface of libropedyn, planar rope dynamics in-process.
 *
 * A simulation is an instance made from a scene (a scene file, or its namelist text):
 *
 *     ropedyn_t *sim;
 *     double force[2];
 *     if (ropedyn_create_from_file("input/paper.nml", &sim) != ROPEDYN_OK ||
 *         ropedyn_set(sim, "supports.top_motion=coupled") != ROPEDYN_OK ||
 *         ropedyn_init(sim, 0) != ROPEDYN_OK) {
 *         fprintf(stderr, "ropedyn: error: %s\n", ropedyn_last_error(sim));
 *         ropedyn_destroy(sim);
 *         return 1;
 *     }
 *     for (int k = 1; k <= 1000; k++) {
 *         double p[2] = {0.0, 0.05 * sin(k * 1e-3)}, v[2] = {0.0, 0.05 * cos(k * 1e-3)};
 *         ropedyn_set_support(sim, ROPEDYN_TOP, p, v);
 *         ropedyn_advance(sim, k * 1e-3);
 *         ropedyn_reaction(sim, ROPEDYN_TOP, force);
 *     }
 *     ropedyn_destroy(sim);
 *
 * Every function that can fail returns a status: ROPEDYN_OK (0) or the exit code the
 * command line gives for that kind of error; ropedyn_last_error(sim) is then the message
 * the command line prints after "ropedyn: error: ". A create function gives an instance
 * even when it fails (so that its message can be read): every other call on it returns
 * the same error; destroy it. A NULL instance, or NULL for where a create function puts
 * it, gives status 2 and no message; a NULL where a call reads or writes its values gives
 * status 2 and a message (but the arrays of ropedyn_forces and the results of
 * ropedyn_run, which may be NULL). Texts returned (const char *) belong to the instance
 * and stay valid until the next call on it.
 *
 * Frame and units: x points down (gravity), y horizontal; SI units (m, s, N, J). The
 * supports are ROPEDYN_TOP and ROPEDYN_BOTTOM.
 *
 * Instances are independent, and the calls are safe from any thread: the library runs
 * one call at a time (a process-wide lock; docs/reference/api.md, "Threads"), so threads
 * do not integrate in parallel. The library catches no signals. A simulation writes no
 * file; ropedyn_run writes one only when given its name.
 *
 * The manual's API page (docs/reference/api.md) describes each call, the coupling rule
 * and what of a command-line run applies. */
#ifndef ROPEDYN_H
#define ROPEDYN_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes: the command line's exit codes. */
#define ROPEDYN_OK 0
#define ROPEDYN_ERROR_INPUT 2    /* bad scene, bad argument, or a call out of order */
#define ROPEDYN_ERROR_SOLVER 3   /* the integration failed */
#define ROPEDYN_ERROR_IO 4       /* an output file could not be written */
#define ROPEDYN_ERROR_INTERNAL 5 /* a bug: an invariant did not hold */

/* The supports. */
#define ROPEDYN_TOP 0
#define ROPEDYN_BOTTOM 1

typedef struct ropedyn ropedyn_t;                   /* an instance (opaque) */
typedef struct ropedyn_snapshot ropedyn_snapshot_t; /* a kept state (opaque) */

/* The library's version, e.g. "0.1.0+g1a2b3c4". */
const char *ropedyn_version(void);

/* Create an instance from a scene file (relative paths in it are relative to its
 * directory; its default output file is out/NAME.h5) or from namelist text named `name`
 * (NULL: "scene"; it plays the file's part in messages and default names). */
int ropedyn_create_from_file(const char *path, ropedyn_t **sim);
int ropedyn_create_from_text(const char *text, const char *name, ropedyn_t **sim);

/* Change the scene as `--set group.key=value` does, e.g. "model.elements=40" (before
 * ropedyn_init); several settings separated by new lines are checked together (as several
 * --set are). A bad setting leaves the scene as it was. */
int ropedyn_set(ropedyn_t *sim, const char *setting);

/* The effective scene as namelist text (every key; reads in again to the same scene), and
 * the scene's warnings (one a line, "" for none). */
int ropedyn_scene_text(ropedyn_t *sim, const char **text);
int ropedyn_warnings(ropedyn_t *sim, const char **text);

/* Build the simulation at the scene's initial state, or with from_statics != 0 at its
 * static equilibrium (at rest). */
int ropedyn_init(ropedyn_t *sim, int from_statics);

/* Integrate to time t (s, not before the time reached; the scene's t_end does not stop
 * it). A failed integration keeps the last good state and ends the simulation: later
 * calls of ropedyn_advance, ropedyn_set_state, ropedyn_set_support and ropedyn_save
 * return the same error until ropedyn_restore; the reads give the last good state. An
 * integration that has created more than a tenth of the rope's energy scale (looked at up
 * to twice per output interval) fails too, keeping the state of the last look; a state
 * set by ropedyn_set_state starts the count again. One that has spent the step budget
 * fails too: solver.max_steps counts every step since ropedyn_init (those before a
 * ropedyn_restore too), and its default follows the scene's t_end. */
int ropedyn_advance(ropedyn_t *sim, double t);

/* The time reached (s); the number of elements n and of unknowns of the ODE state. */
int ropedyn_time(ropedyn_t *sim, double *t);
int ropedyn_size(ropedyn_t *sim, int *elements, int *state_size);

/* The ODE state (state_size values; the layout of /state/y in a run file), and a new one
 * at the current time (the integrator starts again from it). */
int ropedyn_get_state(ropedyn_t *sim, double *y, int size);
int ropedyn_set_state(ropedyn_t *sim, const double *y, int size);

/* The rope now: `count` = 2n end points A_1, B_1, A_2, ... as x, y pairs (xy holds
 * 2 count values: /rope/points of a record); the axial force, shear force (N) and bending
 * moment (N m) at the joints 0 (top end) .. n (joints = n + 1; any array may be NULL); the
 * force of a support on the rope (N, x and y; 0 for a free end); a support's anchor (m;
 * NaN for a free end); the energies (J): kinetic, elastic, gravity, dissipated, external
 * work, total (kinetic + elastic + gravity). */
int ropedyn_points(ropedyn_t *sim, double *xy, int count);
int ropedyn_forces(ropedyn_t *sim, double *axial, double *shear, double *moment, int joints);
int ropedyn_reaction(ropedyn_t *sim, int support, double force[2]);
int ropedyn_support_position(ropedyn_t *sim, int support, double position[2]);
int ropedyn_energy(ropedyn_t *sim, double energy[6]);

/* A coupled support (&supports top_motion = 'coupled', or bottom_motion): its position
 * (m) and velocity (m/s) at the time of the next ropedyn_advance. In between, it moves on
 * the cubic Hermite curve from its position and velocity now to those; not given, it goes
 * on with its velocity now. */
int ropedyn_set_support(ropedyn_t *sim, int support, const double position[2],
                        const double velocity[2]);

/* Keep the state now in memory, and go back to it (also after a failure). The
 * simulation goes on after ropedyn_save exactly as it will after ropedyn_restore of that
 * snapshot (the integrator starts again at both). A snapshot belongs to the caller. */
int ropedyn_save(ropedyn_t *sim, ropedyn_snapshot_t **snapshot);
int ropedyn_restore(ropedyn_t *sim, const ropedyn_snapshot_t *snapshot);
void ropedyn_snapshot_destroy(ropedyn_snapshot_t *snapshot);

/* Run the scene from its start to t_end as `ropedyn run` does (same records, order
 * safety, statuses), apart from the instance's simulation: into the file `output`, or with
 * output NULL or "" into memory, whose bytes (an HDF5 file) *image and *size then give,
 * also after a failed integration (the records up to the failure); NULL and 0 for a run
 * into a file. The image belongs to the instance and stays valid until its next
 * ropedyn_run or ropedyn_destroy. `image` and `size` may be NULL. */
int ropedyn_run(ropedyn_t *sim, const char *output, const void **image, size_t *size);

/* The message of the last call that failed on this instance ("" when it succeeded; NULL
 * for a NULL instance). */
const char *ropedyn_last_error(const ropedyn_t *sim);

/* Free the instance (NULL: nothing). */
void ropedyn_destroy(ropedyn_t *sim);

#ifdef __cplusplus
}
#endif

#endif /* ROPEDYN_H */
