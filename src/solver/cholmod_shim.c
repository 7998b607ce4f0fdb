/* The few CHOLMOD calls voiga_solver_cholmod needs, behind plain C functions:
 * CHOLMOD's structs (cholmod_common is large and its layout changes between
 * versions) stay on this side, so the Fortran interface is scalars and arrays.
 * Every function returns 0 on success, 1 when the matrix is not positive
 * definite, -1 on any other CHOLMOD failure (out of memory, invalid input).
 * Nothing is printed: Common->print = 0.
 *
 * CHOLMOD 5.x runs the small loops of its supernodal factorization (scattering A
 * into each supernode) on CHOLMOD_OMP_NUM_THREADS threads, a number fixed when it
 * was compiled (4 in Debian 12's 5.12), whatever OMP_NUM_THREADS says. On hertz m4
 * NN2.2 (2 cores, OMP_NUM_THREADS=1) those threads, woken and put to sleep per
 * supernode, cost about 0.15 s of a 0.6 s run (docs/performance.md, "Threads").
 * When OpenMP allows fewer threads than CHOLMOD asks for, voiga runs those loops
 * serially: with max-active-levels 0 every parallel region is inactive, so it runs
 * on the calling thread. The OpenMP functions are looked up with dlsym, so a
 * CHOLMOD built without OpenMP needs nothing. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <suitesparse/cholmod.h>

typedef struct {
    int (*max_threads)(void);
    int (*max_levels)(void);
    void (*set_max_levels)(int);
} openmp_calls;

/* The OpenMP runtime's calls, or NULLs when no OpenMP runtime is loaded. */
static openmp_calls openmp(void)
{
    openmp_calls o;
    o.max_threads = (int (*)(void))dlsym(RTLD_DEFAULT, "omp_get_max_threads");
    o.max_levels = (int (*)(void))dlsym(RTLD_DEFAULT, "omp_get_max_active_levels");
    o.set_max_levels = (void (*)(int))dlsym(RTLD_DEFAULT, "omp_set_max_active_levels");
    if (!o.max_threads || !o.max_levels || !o.set_max_levels) o.max_threads = NULL;
    return o;
}

/* Make CHOLMOD's parallel regions run serially when OpenMP allows fewer threads
 * than CHOLMOD_OMP_NUM_THREADS; returns the max-active-levels to restore (-1: none
 * changed). */
static int serial_begin(void)
{
    openmp_calls o = openmp();
    int levels;
    if (!o.max_threads || o.max_threads() >= CHOLMOD_OMP_NUM_THREADS) return -1;
    levels = o.max_levels();
    o.set_max_levels(0);
    return levels;
}

static void serial_end(int levels)
{
    openmp_calls o;
    if (levels < 0) return;
    o = openmp();
    o.set_max_levels(levels);
}

/* 1 when CHOLMOD's loops would run serially now (the rule of serial_begin), for the tests. */
int voiga_cholmod_serial(void)
{
    openmp_calls o = openmp();
    return !o.max_threads || o.max_threads() < CHOLMOD_OMP_NUM_THREADS;
}

typedef struct {
    cholmod_common common;
    cholmod_factor *factor;
    int n;
} voiga_cholmod;

static double log10_determinant(const cholmod_factor *f)
{
    const double *x = (const double *)f->x;
    double logdet = 0.0;
    size_t j, s;
    if (f->is_super) {
        const int *super = (const int *)f->super, *pi = (const int *)f->pi, *px = (const int *)f->px;
        for (s = 0; s < f->nsuper; s++) {
            int k1 = super[s], k2 = super[s + 1], nsrow = pi[s + 1] - pi[s], k;
            for (k = 0; k < k2 - k1; k++) logdet += 2.0 * log10(fabs(x[px[s] + k + (size_t)k * nsrow]));
        }
    } else {
        const int *p = (const int *)f->p;
        for (j = 0; j < f->n; j++) logdet += (f->is_ll ? 2.0 : 1.0) * log10(fabs(x[p[j]]));
    }
    return logdet;
}

/* Cholesky factorization of the symmetric n x n matrix whose lower triangle is
 * given in CSC form (0-based colptr [n+1], rowind, values; entries above the
 * diagonal are ignored). On success *handle owns the factor; *flops is the
 * factorization's flop count, *log10_det log10 det A and *rcond CHOLMOD's
 * reciprocal condition estimate, (min / max diagonal of L)^2. */
int voiga_cholmod_factor(int n, const int *colptr, const int *rowind, const double *values, void **handle,
                         double *flops, double *log10_det, double *rcond)
{
    voiga_cholmod *h;
    cholmod_sparse *a;
    int j, k, nnz = 0, status, levels;
    *handle = NULL;
    h = calloc(1, sizeof *h);
    if (!h) return -1;
    cholmod_start(&h->common);
    h->common.print = 0;
    h->common.error_handler = NULL;
    h->n = n;
    for (j = 0; j < n; j++)
        for (k = colptr[j]; k < colptr[j + 1]; k++)
            if (rowind[k] >= j) nnz++;
    a = cholmod_allocate_sparse(n, n, nnz, 1, 1, -1, CHOLMOD_REAL, &h->common);
    if (!a) {
        cholmod_finish(&h->common);
        free(h);
        return -1;
    }
    {
        int *ap = (int *)a->p, *ai = (int *)a->i, q = 0;
        double *ax = (double *)a->x;
        for (j = 0; j < n; j++) {
            ap[j] = q;
            for (k = colptr[j]; k < colptr[j + 1]; k++)
                if (rowind[k] >= j) {
                    ai[q] = rowind[k];
                    ax[q++] = values[k];
                }
        }
        ap[n] = q;
    }
    levels = serial_begin();
    h->factor = cholmod_analyze(a, &h->common);
    status = h->factor ? 0 : -1;
    if (status == 0 && !cholmod_factorize(a, h->factor, &h->common)) status = -1;
    serial_end(levels);
    if (status == 0 && (h->common.status == CHOLMOD_NOT_POSDEF || h->factor->minor < (size_t)n)) status = 1;
    if (status == 0 && h->common.status < CHOLMOD_OK) status = -1;
    cholmod_free_sparse(&a, &h->common);
    if (status != 0) {
        if (h->factor) cholmod_free_factor(&h->factor, &h->common);
        cholmod_finish(&h->common);
        free(h);
        return status;
    }
    *flops = h->common.fl;
    *log10_det = log10_determinant(h->factor);
    *rcond = cholmod_rcond(h->factor, &h->common);
    *handle = h;
    return 0;
}

/* Solve A X = B for nrhs right-hand sides (B, X: n x nrhs, column-major). */
int voiga_cholmod_solve(void *handle, int nrhs, const double *b, double *x)
{
    voiga_cholmod *h = handle;
    cholmod_dense *bd, *xd;
    size_t size = (size_t)h->n * (size_t)nrhs;
    int levels;
    bd = cholmod_allocate_dense(h->n, nrhs, h->n, CHOLMOD_REAL, &h->common);
    if (!bd) return -1;
    memcpy(bd->x, b, size * sizeof(double));
    levels = serial_begin();
    xd = cholmod_solve(CHOLMOD_A, h->factor, bd, &h->common);
    serial_end(levels);
    cholmod_free_dense(&bd, &h->common);
    if (!xd) return -1;
    memcpy(x, xd->x, size * sizeof(double));
    cholmod_free_dense(&xd, &h->common);
    return 0;
}

/* Free the factor and the handle (NULL: nothing to do). */
void voiga_cholmod_free(void *handle)
{
    voiga_cholmod *h = handle;
    if (!h) return;
    if (h->factor) cholmod_free_factor(&h->factor, &h->common);
    cholmod_finish(&h->common);
    free(h);
}
