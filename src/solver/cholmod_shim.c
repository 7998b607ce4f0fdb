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

/* The OpenMP runtime's calls, looked up once; max_threads NULL when no OpenMP
 * runtime is loaded. */
static const openmp_calls *openmp(void)
{
    static openmp_calls o;
    static int looked = 0;
    if (!looked) {
        o.max_threads = (int (*)(void))dlsym(RTLD_DEFAULT, "omp_get_max_threads");
        o.max_levels = (int (*)(void))dlsym(RTLD_DEFAULT, "omp_get_max_active_levels");
        o.set_max_levels = (void (*)(int))dlsym(RTLD_DEFAULT, "omp_set_max_active_levels");
        if (!o.max_threads || !o.max_levels || !o.set_max_levels) o.max_threads = NULL;
        looked = 1;
    }
    return &o;
}

/* 1 when CHOLMOD's loops run serially now: no OpenMP, or OpenMP allows fewer
 * threads than CHOLMOD_OMP_NUM_THREADS (then serial_begin makes them serial). */
int voiga_cholmod_serial(void)
{
    const openmp_calls *o = openmp();
    return !o->max_threads || o->max_threads() < CHOLMOD_OMP_NUM_THREADS;
}

/* Make CHOLMOD's parallel regions run serially when voiga_cholmod_serial says so;
 * returns the max-active-levels to restore (-1: none changed). */
static int serial_begin(void)
{
    const openmp_calls *o = openmp();
    int levels;
    if (!o->max_threads || !voiga_cholmod_serial()) return -1;
    levels = o->max_levels();
    o->set_max_levels(0);
    return levels;
}

static void serial_end(int levels)
{
    if (levels >= 0) openmp()->set_max_levels(levels);
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

/* The lower triangle of the n x n CSC matrix (0-based) as a CHOLMOD matrix (stype -1). */
static cholmod_sparse *lower_triangle(int n, const int *colptr, const int *rowind, const double *values,
                                      cholmod_common *common)
{
    cholmod_sparse *a;
    int j, k, nnz = 0, q = 0, *ap, *ai;
    double *ax;
    for (j = 0; j < n; j++)
        for (k = colptr[j]; k < colptr[j + 1]; k++)
            if (rowind[k] >= j) nnz++;
    a = cholmod_allocate_sparse(n, n, nnz, 1, 1, -1, CHOLMOD_REAL, common);
    if (!a) return NULL;
    ap = (int *)a->p;
    ai = (int *)a->i;
    ax = (double *)a->x;
    for (j = 0; j < n; j++) {
        ap[j] = q;
        for (k = colptr[j]; k < colptr[j + 1]; k++)
            if (rowind[k] >= j) {
                ai[q] = rowind[k];
                ax[q++] = values[k];
            }
    }
    ap[n] = q;
    return a;
}

/* The symbolic analysis of a with the nlast DOFs `last` (0-based, distinct) ordered
 * after all others: CAMD's fill-reducing ordering with two constraint sets, taken
 * as given (not postordered, which could interleave the sets). NULL when CAMD or the analysis fails, or the ordering
 * does not end with `last`. */
static cholmod_factor *analyze_last(cholmod_sparse *a, int nlast, const int *last, cholmod_common *common)
{
    int n = (int)a->nrow, k, ok = 1;
    int *cmember = calloc((size_t)n, sizeof(int)), *perm = malloc((size_t)n * sizeof(int));
    cholmod_factor *f = NULL;
    if (cmember && perm) {
        for (k = 0; k < nlast; k++) cmember[last[k]] = 1;
        if (cholmod_camd(a, NULL, 0, cmember, perm, common)) {
            common->nmethods = 1;
            common->method[0].ordering = CHOLMOD_GIVEN;
            common->postorder = 0;
            f = cholmod_analyze_p(a, perm, NULL, 0, common);
        }
    }
    if (f) {
        const int *p = (const int *)f->Perm;
        for (k = n - nlast; k < n; k++) ok = ok && cmember[p[k]] == 1;
        if (!ok) cholmod_free_factor(&f, common);
    }
    free(cmember);
    free(perm);
    return f;
}

/* Cholesky factorization of the symmetric n x n matrix whose lower triangle is
 * given in CSC form (0-based colptr [n+1], rowind, values; entries above the
 * diagonal are ignored). With nlast > 0, the DOFs `last` [nlast] (0-based) come
 * last in the fill-reducing ordering, so the trailing nlast x nlast block of L is
 * theirs (voiga_cholmod_trailing); the status is -2 when that ordering fails. On
 * success *handle owns the factor; *flops is the factorization's flop count,
 * *log10_det log10 det A and *rcond CHOLMOD's reciprocal condition estimate,
 * (min / max diagonal of L)^2. */
int voiga_cholmod_factor(int n, const int *colptr, const int *rowind, const double *values, int nlast,
                         const int *last, void **handle, double *flops, double *log10_det, double *rcond)
{
    voiga_cholmod *h;
    cholmod_sparse *a;
    int status, levels;
    *handle = NULL;
    h = calloc(1, sizeof *h);
    if (!h) return -1;
    cholmod_start(&h->common);
    h->common.print = 0;
    h->common.error_handler = NULL;
    /* always L L^T, which the forward and backward solves (sys 1, 2) and
     * voiga_cholmod_trailing take the factor to be */
    h->common.supernodal = CHOLMOD_SUPERNODAL;
    h->n = n;
    a = lower_triangle(n, colptr, rowind, values, &h->common);
    if (!a) {
        cholmod_finish(&h->common);
        free(h);
        return -1;
    }
    levels = serial_begin();
    h->factor = nlast > 0 ? analyze_last(a, nlast, last, &h->common) : cholmod_analyze(a, &h->common);
    status = h->factor ? 0 : (nlast > 0 ? -2 : -1);
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

/* The fill-reducing ordering: position k of the factor holds DOF perm[k] (0-based, [n]). */
void voiga_cholmod_perm(void *handle, int *perm)
{
    voiga_cholmod *h = handle;
    memcpy(perm, h->factor->Perm, (size_t)h->n * sizeof(int));
}

/* The trailing m x m block of L (column-major, lower triangle; zeros above) of a
 * supernodal factor; returns -1 for a simplicial one. */
int voiga_cholmod_trailing(void *handle, int m, double *l)
{
    voiga_cholmod *h = handle;
    const cholmod_factor *f = h->factor;
    const int *super = (const int *)f->super, *pi = (const int *)f->pi, *px = (const int *)f->px;
    const int *rows = (const int *)f->s;
    const double *x = (const double *)f->x;
    int n0 = h->n - m, s, k, i;
    if (!f->is_super) return -1;
    memset(l, 0, (size_t)m * (size_t)m * sizeof(double));
    for (s = 0; s < (int)f->nsuper; s++) {
        int k1 = super[s], k2 = super[s + 1], nsrow = pi[s + 1] - pi[s];
        if (k2 <= n0) continue;
        for (k = k1 > n0 ? k1 : n0; k < k2; k++)
            for (i = k - k1; i < nsrow; i++)
                l[(rows[pi[s] + i] - n0) + (size_t)(k - n0) * m] = x[px[s] + i + (size_t)(k - k1) * nsrow];
    }
    return 0;
}

/* Solve for nrhs right-hand sides (B, X: n x nrhs, column-major): sys 0 A X = B,
 * 1 L X = B, 2 L^T X = B (L of the permuted matrix: no permutation applied). */
int voiga_cholmod_solve(void *handle, int sys, int nrhs, const double *b, double *x)
{
    static const int systems[3] = {CHOLMOD_A, CHOLMOD_L, CHOLMOD_Lt};
    voiga_cholmod *h = handle;
    cholmod_dense *bd, *xd;
    size_t size = (size_t)h->n * (size_t)nrhs;
    int levels;
    if (sys < 0 || sys > 2) return -1;
    bd = cholmod_allocate_dense(h->n, nrhs, h->n, CHOLMOD_REAL, &h->common);
    if (!bd) return -1;
    memcpy(bd->x, b, size * sizeof(double));
    levels = serial_begin();
    xd = cholmod_solve(systems[sys], h->factor, bd, &h->common);
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
