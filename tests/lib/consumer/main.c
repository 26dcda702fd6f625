/* consumer_c SCENE: the scene's rope advanced 0.5 s; prints its top tension. */
#include <stdio.h>
#include <ropedyn.h>

int main(int argc, char **argv)
{
    ropedyn_t *sim = NULL;
    double force[2];
    if (argc < 2 || ropedyn_create_from_file(argv[1], &sim) != ROPEDYN_OK ||
        ropedyn_set(sim, "model.elements=8") != ROPEDYN_OK || ropedyn_init(sim, 0) != ROPEDYN_OK ||
        ropedyn_advance(sim, 0.5) != ROPEDYN_OK ||
        ropedyn_reaction(sim, ROPEDYN_TOP, force) != ROPEDYN_OK) {
        fprintf(stderr, "ropedyn: error: %s\n", ropedyn_last_error(sim));
        ropedyn_destroy(sim);
        return 1;
    }
    printf("c %.17g %.17g\n", force[0], force[1]);
    ropedyn_destroy(sim);
    return 0;
}
