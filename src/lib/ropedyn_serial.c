/* The C interface one call at a time (include/ropedyn.h; docs/reference/api.md, "Threads").

   Every function of the header is the Fortran one of src/lib/ropedyn_capi.f90 (bound to
   the same name with the prefix ropedyn_f_, not exported: src/lib/ropedyn.map) called with
   one process-wide lock held. gfortran 12 keeps the length of a character function's
   result (a `character(len=:), allocatable` result) in a static variable at each place
   of call, also with -frecursive: two threads in the same place at once exchange their
   lengths, and the scene reader, the messages and the logs are full of such places (two
   threads creating simulations corrupted the heap). The lock makes the calls safe from any
   thread; they run one at a time. ropedyn_version returns a constant and takes no lock. */
#include <pthread.h>
#include <stddef.h>

#include "ropedyn.h"

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;

/* the Fortran functions (ropedyn_capi.f90) */
const char *ropedyn_f_version(void);
int ropedyn_f_create_from_file(const char *path, ropedyn_t **sim);
int ropedyn_f_create_from_text(const char *text, const char *name, ropedyn_t **sim);
int ropedyn_f_set(ropedyn_t *sim, const char *setting);
int ropedyn_f_scene_text(ropedyn_t *sim, const char **text);
int ropedyn_f_warnings(ropedyn_t *sim, const char **text);
int ropedyn_f_init(ropedyn_t *sim, int from_statics);
int ropedyn_f_advance(ropedyn_t *sim, double t);
int ropedyn_f_time(ropedyn_t *sim, double *t);
int ropedyn_f_size(ropedyn_t *sim, int *elements, int *state_size);
int ropedyn_f_get_state(ropedyn_t *sim, double *y, int size);
int ropedyn_f_set_state(ropedyn_t *sim, const double *y, int size);
int ropedyn_f_points(ropedyn_t *sim, double *xy, int count);
int ropedyn_f_forces(ropedyn_t *sim, double *axial, double *shear, double *moment, int joints);
int ropedyn_f_reaction(ropedyn_t *sim, int support, double force[2]);
int ropedyn_f_support_position(ropedyn_t *sim, int support, double position[2]);
int ropedyn_f_energy(ropedyn_t *sim, double energy[6]);
int ropedyn_f_set_support(ropedyn_t *sim, int support, const double position[2], const double velocity[2]);
int ropedyn_f_save(ropedyn_t *sim, ropedyn_snapshot_t **snapshot);
int ropedyn_f_restore(ropedyn_t *sim, const ropedyn_snapshot_t *snapshot);
void ropedyn_f_snapshot_destroy(ropedyn_snapshot_t *snapshot);
int ropedyn_f_run(ropedyn_t *sim, const char *output, const void **image, size_t *size);
const char *ropedyn_f_last_error(const ropedyn_t *sim);
void ropedyn_f_destroy(ropedyn_t *sim);

const char *ropedyn_version(void)
{
    return ropedyn_f_version();
}

int ropedyn_create_from_file(const char *path, ropedyn_t **sim)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_create_from_file(path, sim);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_create_from_text(const char *text, const char *name, ropedyn_t **sim)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_create_from_text(text, name, sim);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_set(ropedyn_t *sim, const char *setting)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_set(sim, setting);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_scene_text(ropedyn_t *sim, const char **text)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_scene_text(sim, text);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_warnings(ropedyn_t *sim, const char **text)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_warnings(sim, text);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_init(ropedyn_t *sim, int from_statics)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_init(sim, from_statics);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_advance(ropedyn_t *sim, double t)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_advance(sim, t);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_time(ropedyn_t *sim, double *t)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_time(sim, t);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_size(ropedyn_t *sim, int *elements, int *state_size)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_size(sim, elements, state_size);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_get_state(ropedyn_t *sim, double *y, int size)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_get_state(sim, y, size);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_set_state(ropedyn_t *sim, const double *y, int size)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_set_state(sim, y, size);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_points(ropedyn_t *sim, double *xy, int count)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_points(sim, xy, count);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_forces(ropedyn_t *sim, double *axial, double *shear, double *moment, int joints)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_forces(sim, axial, shear, moment, joints);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_reaction(ropedyn_t *sim, int support, double force[2])
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_reaction(sim, support, force);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_support_position(ropedyn_t *sim, int support, double position[2])
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_support_position(sim, support, position);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_energy(ropedyn_t *sim, double energy[6])
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_energy(sim, energy);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_set_support(ropedyn_t *sim, int support, const double position[2], const double velocity[2])
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_set_support(sim, support, position, velocity);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_save(ropedyn_t *sim, ropedyn_snapshot_t **snapshot)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_save(sim, snapshot);
    pthread_mutex_unlock(&lock);
    return result;
}

int ropedyn_restore(ropedyn_t *sim, const ropedyn_snapshot_t *snapshot)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_restore(sim, snapshot);
    pthread_mutex_unlock(&lock);
    return result;
}

void ropedyn_snapshot_destroy(ropedyn_snapshot_t *snapshot)
{
    pthread_mutex_lock(&lock);
    ropedyn_f_snapshot_destroy(snapshot);
    pthread_mutex_unlock(&lock);
}

int ropedyn_run(ropedyn_t *sim, const char *output, const void **image, size_t *size)
{
    pthread_mutex_lock(&lock);
    int result = ropedyn_f_run(sim, output, image, size);
    pthread_mutex_unlock(&lock);
    return result;
}

const char *ropedyn_last_error(const ropedyn_t *sim)
{
    pthread_mutex_lock(&lock);
    const char *result = ropedyn_f_last_error(sim);
    pthread_mutex_unlock(&lock);
    return result;
}

void ropedyn_destroy(ropedyn_t *sim)
{
    pthread_mutex_lock(&lock);
    ropedyn_f_destroy(sim);
    pthread_mutex_unlock(&lock);
}
