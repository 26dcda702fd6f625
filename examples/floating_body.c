/* A floating body moored by a rope: the body's two degrees of freedom (heave x, down, and
 * surge y, sideways) are integrated here; the rope is ropedyn's, its top end coupled to
 * the body (a fairlead), its bottom end pinned to an anchor on the sea floor.
 *
 *     cc floating_body.c -I PREFIX/include -L PREFIX/lib -Wl,-rpath,PREFIX/lib \
 *        -lropedyn -lm -o floating_body
 *     ./floating_body [T_END] [EVERY]
 *
 * prints `t x y fx fy` (s, m, m, N, N: the body's position and the rope's force on it)
 * every EVERY seconds (default 0.5) up to T_END (default 10 s), then the mean position.
 *
 * The body: mass M, a hydrostatic spring in heave (its weight and buoyancy balance at
 * x = 0), linear damping in both directions, and a wave force in both. Every DT the two
 * codes exchange: the body's position and velocity at the end of the step go to the rope
 * (ropedyn_set_support), the rope is advanced there, and its reaction comes back (the rope
 * pulls the body with minus the force of the support on the rope). The body's step is
 * the semi-implicit Euler method with the rope's force of the step's start. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "ropedyn.h"

static const char *SCENE =
    "&rope\n"
    "    length = 1.0, density = 6000.0, diameter = 0.005, young_modulus = 35.0e6\n"
    "    shear_modulus = 14.0e6, normal_damping = 1.0e3, tangential_damping = 400.0\n"
    "/\n"
    "&model\n    kind = 'rfem', elements = 20\n/\n"
    "&supports\n"
    "    top = 'pinned', top_anchor = 0.0, 0.0, top_motion = 'coupled'\n"
    "    bottom = 'pinned', bottom_anchor = 0.8, 0.5\n"
    "/\n";

#define M 2.0          /* kg: the body's mass */
#define K_HEAVE 200.0  /* N/m: hydrostatic stiffness */
#define DAMPING 2.0    /* N s/m: in heave and surge */
#define WAVE_X 0.5     /* N: wave force amplitudes, heave and surge */
#define WAVE_Y 1.0
#define OMEGA 3.14159265358979 /* rad/s: 0.5 Hz */
#define DT 1e-3        /* s: the exchange step */

static int fail(ropedyn_t *sim)
{
    fprintf(stderr, "floating_body: ropedyn: error: %s\n", ropedyn_last_error(sim));
    ropedyn_destroy(sim);
    return 1;
}

int main(int argc, char **argv)
{
    double t_end = argc > 1 ? atof(argv[1]) : 10.0;
    double every = argc > 2 ? atof(argv[2]) : 0.5;
    ropedyn_t *sim = NULL;
    /* the rope at its static equilibrium under the body, at rest */
    if (ropedyn_create_from_text(SCENE, "mooring", &sim) != ROPEDYN_OK
        || ropedyn_init(sim, 1) != ROPEDYN_OK)
        return fail(sim);

    double p[2] = {0.0, 0.0}, v[2] = {0.0, 0.0}, reaction[2], f[2];
    double mean[2] = {0.0, 0.0};
    long steps = lround(t_end / DT), print_every = lround(every / DT);
    if (ropedyn_reaction(sim, ROPEDYN_TOP, reaction) != ROPEDYN_OK)
        return fail(sim);
    for (long k = 0; k < steps; k++) {
        double t = k * DT;
        f[0] = -reaction[0];
        f[1] = -reaction[1];
        if (k % print_every == 0)
            printf("%.3f %.6f %.6f %.6f %.6f\n", t, p[0], p[1], f[0], f[1]);
        double a[2] = {
            (WAVE_X * sin(OMEGA * t) - K_HEAVE * p[0] - DAMPING * v[0] + f[0]) / M,
            (WAVE_Y * sin(OMEGA * t) - DAMPING * v[1] + f[1]) / M};
        for (int i = 0; i < 2; i++) {
            v[i] += DT * a[i];
            p[i] += DT * v[i];
            mean[i] += p[i] / steps;
        }
        if (ropedyn_set_support(sim, ROPEDYN_TOP, p, v) != ROPEDYN_OK
            || ropedyn_advance(sim, (k + 1) * DT) != ROPEDYN_OK
            || ropedyn_reaction(sim, ROPEDYN_TOP, reaction) != ROPEDYN_OK)
            return fail(sim);
    }
    printf("mean %.6f %.6f\n", mean[0], mean[1]);
    ropedyn_destroy(sim);
    return 0;
}
