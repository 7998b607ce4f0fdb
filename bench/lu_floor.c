/* What one sparse LU of a voiga tangent costs with the SuiteSparse factorizations on this
 * machine (docs/performance-ironing.md).
 *
 * Input: a matrix in voiga's CSC form as a stream file: int n, int nnz, int colptr[n+1]
 * (0-based), int rowind[nnz], double values[nnz] (a Fortran `write(u) a%n, size(a%rowind),
 * a%colptr, a%rowind, a%values` with access='stream' in umfpack_factorize writes it).
 *
 *   gcc -O2 bench/lu_floor.c -o build/lu_floor -lumfpack -lklu -lcholmod -lamd -lopenblas
 *   OPENBLAS_NUM_THREADS=1 build/lu_floor tangent.bin
 *
 * Prints the fastest of 60 numeric factorizations (interleaved, symbolic analysis done
 * once) for UMFPACK with its defaults and the Control settings tried, KLU factor and
 * refactor (pivot order kept), and CHOLMOD on the symmetric part (a lower bound only:
 * the frictional tangent is not symmetric).
 */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <suitesparse/umfpack.h>
#include <suitesparse/klu.h>
#include <suitesparse/cholmod.h>

#define REPEAT 60
#define NVAR 6

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

int main(int argc, char **argv) {
    int n, nnz;
    FILE *f = argc > 1 ? fopen(argv[1], "rb") : NULL;
    if (!f || fread(&n, 4, 1, f) != 1 || fread(&nnz, 4, 1, f) != 1) {
        fprintf(stderr, "usage: lu_floor MATRIX.bin (see the header of bench/lu_floor.c)\n");
        return 2;
    }
    int *ap = malloc(4 * (n + 1)), *ai = malloc(4 * nnz);
    double *ax = malloc(8 * nnz);
    if (fread(ap, 4, n + 1, f) != (size_t)(n + 1) || fread(ai, 4, nnz, f) != (size_t)nnz ||
        fread(ax, 8, nnz, f) != (size_t)nnz) {
        fprintf(stderr, "lu_floor: %s is shorter than its header says\n", argv[1]);
        return 2;
    }
    fclose(f);
    printf("n %d, nnz %d\n", n, nnz);

    const char *name[NVAR] = {"umfpack default", "umfpack no scaling", "umfpack singletons off",
                              "umfpack ordering best", "klu factor", "klu refactor"};
    double control[4][UMFPACK_CONTROL], info[UMFPACK_INFO], best[NVAR];
    void *sym[4], *num;
    for (int v = 0; v < 4; v++) umfpack_di_defaults(control[v]);
    control[1][UMFPACK_SCALE] = UMFPACK_SCALE_NONE;
    control[2][UMFPACK_SINGLETONS] = 0;
    control[3][UMFPACK_ORDERING] = UMFPACK_ORDERING_BEST;
    for (int v = 0; v < 4; v++) umfpack_di_symbolic(n, n, ap, ai, ax, &sym[v], control[v], info);
    klu_common kc;
    klu_defaults(&kc);
    kc.btf = 0;
    klu_symbolic *ks = klu_analyze(n, ap, ai, &kc);
    klu_numeric *kn = klu_factor(ap, ai, ax, ks, &kc);
    for (int v = 0; v < NVAR; v++) best[v] = 1e30;
    for (int r = 0; r < REPEAT; r++) {
        for (int v = 0; v < NVAR; v++) {
            double t0 = now();
            if (v < 4) {
                umfpack_di_numeric(ap, ai, ax, sym[v], &num, control[v], info);
            } else if (v == 4) {
                klu_free_numeric(&kn, &kc);
                kn = klu_factor(ap, ai, ax, ks, &kc);
            } else {
                klu_refactor(ap, ai, ax, ks, kn, &kc);
            }
            double t = now() - t0;
            if (t < best[v]) best[v] = t;
            if (v < 4) {
                if (r == 0) printf("%-24s flops %.3g, nnz(L) %.0f\n", name[v], info[UMFPACK_FLOPS], info[UMFPACK_LNZ]);
                umfpack_di_free_numeric(&num);
            }
        }
    }
    for (int v = 0; v < NVAR; v++) printf("%-24s %8.3f ms\n", name[v], 1e3 * best[v]);

    /* CHOLMOD on (A + A^T)/2: what a Cholesky-type factorization of this size costs */
    cholmod_common cc;
    cholmod_start(&cc);
    cc.print = 0;
    cholmod_sparse *a = cholmod_allocate_sparse(n, n, nnz, 1, 1, 0, CHOLMOD_REAL, &cc);
    for (int i = 0; i <= n; i++) ((int *)a->p)[i] = ap[i];
    for (int i = 0; i < nnz; i++) {
        ((int *)a->i)[i] = ai[i];
        ((double *)a->x)[i] = ax[i];
    }
    cholmod_sparse *at = cholmod_transpose(a, 1, &cc);
    double half[2] = {0.5, 0.0};
    cholmod_sparse *s = cholmod_add(a, at, half, half, 1, 1, &cc);
    s->stype = 1;
    for (int sn = 0; sn < 2; sn++) {
        cc.supernodal = sn ? CHOLMOD_SUPERNODAL : CHOLMOD_SIMPLICIAL;
        cholmod_factor *l = cholmod_analyze(s, &cc);
        double b = 1e30;
        for (int r = 0; r < REPEAT; r++) {
            double t0 = now();
            cholmod_factorize(s, l, &cc);
            double t = now() - t0;
            if (t < b) b = t;
        }
        printf("cholmod %-16s %8.3f ms (flops %.3g; symmetric part, a bound only)\n",
               sn ? "supernodal" : "simplicial", 1e3 * b, cc.fl);
        cholmod_free_factor(&l, &cc);
    }
    cholmod_finish(&cc);
    return 0;
}
