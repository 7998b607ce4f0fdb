/* The symbolic analysis of voiga_solver_supernodal through CHOLMOD: a fill-reducing
 * ordering (AMD) of a symmetric pattern, postordered, and its relaxed supernodes with
 * their row structures. The supernodal LU of voiga_solver_supernodal pivots only
 * inside a supernode's diagonal block, so the structure of L is that of the
 * Cholesky factor of the pattern and U has the transposed structure: CHOLMOD's
 * symbolic supernodal factor describes both. CHOLMOD's structs stay on this side;
 * the Fortran interface is scalars and arrays (as in cholmod_shim.c). Every function
 * returns 0 on success and -1 on a CHOLMOD failure (out of memory, invalid input).
 * Nothing is printed: Common->print = 0. */
#include <stdlib.h>
#include <string.h>
#include <suitesparse/cholmod.h>

typedef struct {
    cholmod_common common;
    cholmod_factor *factor;
} voiga_supernodal;

/* Analyse the symmetric n x n pattern whose lower triangle (diagonal included) is
 * given in CSC form (0-based colptr [n+1], rowind ascending in each column). On success *handle
 * owns the symbolic factor, *nsuper is its number of supernodes and *nrows the total
 * length of their row structures (for `voiga_supernodal_copy`). */
int voiga_supernodal_analyze(int n, const int *colptr, const int *rowind, void **handle, int *nsuper,
                             int *nrows)
{
    voiga_supernodal *h;
    cholmod_sparse *a;
    int nnz = colptr[n];
    *handle = NULL;
    h = calloc(1, sizeof *h);
    if (!h) return -1;
    cholmod_start(&h->common);
    h->common.print = 0;
    h->common.error_handler = NULL;
    h->common.supernodal = CHOLMOD_SUPERNODAL;
    /* AMD alone: on voiga's 2D tangents it gives less fill than METIS/NESDIS or
     * about the same, and costs a fraction of them */
    h->common.nmethods = 1;
    h->common.method[0].ordering = CHOLMOD_AMD;
    h->common.postorder = 1;
    a = cholmod_allocate_sparse(n, n, nnz, 1, 1, -1, CHOLMOD_PATTERN, &h->common);
    if (!a) {
        cholmod_finish(&h->common);
        free(h);
        return -1;
    }
    memcpy(a->p, colptr, (size_t)(n + 1) * sizeof(int));
    memcpy(a->i, rowind, (size_t)nnz * sizeof(int));
    h->factor = cholmod_analyze(a, &h->common);
    cholmod_free_sparse(&a, &h->common);
    if (!h->factor || h->common.status < CHOLMOD_OK || !h->factor->is_super) {
        if (h->factor) cholmod_free_factor(&h->factor, &h->common);
        cholmod_finish(&h->common);
        free(h);
        return -1;
    }
    *nsuper = (int)h->factor->nsuper;
    *nrows = ((const int *)h->factor->pi)[h->factor->nsuper];
    *handle = h;
    return 0;
}

/* Copy the analysis (0-based): perm [n] (perm[k]: the original index of the k-th
 * pivot), super [nsuper+1] (first column of each supernode in the new order), rptr
 * [nsuper+1] and rows [nrows] (the row structure of each supernode, new indices,
 * ascending, its own columns first). */
void voiga_supernodal_copy(void *handle, int *perm, int *super, int *rptr, int *rows)
{
    voiga_supernodal *h = handle;
    cholmod_factor *f = h->factor;
    size_t ns = f->nsuper;
    memcpy(perm, f->Perm, f->n * sizeof(int));
    memcpy(super, f->super, (ns + 1) * sizeof(int));
    memcpy(rptr, f->pi, (ns + 1) * sizeof(int));
    memcpy(rows, f->s, (size_t)((const int *)f->pi)[ns] * sizeof(int));
}

/* Free the symbolic factor and the handle (NULL: nothing to do). */
void voiga_supernodal_free(void *handle)
{
    voiga_supernodal *h = handle;
    if (!h) return;
    if (h->factor) cholmod_free_factor(&h->factor, &h->common);
    cholmod_finish(&h->common);
    free(h);
}
