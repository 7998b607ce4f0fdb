/* Thread counts of the BLAS and OpenMP libraries the program happens to be linked
 * with, set at run time. Looked up with dlsym so that any libblas works: OpenBLAS
 * (pthreads or OpenMP build) has openblas_set_num_threads, reference BLAS has no
 * threads and nothing is done. Returns how many of the two setters were found. */
#define _GNU_SOURCE
#include <dlfcn.h>

int voiga_set_library_threads(int n)
{
    int found = 0;
    void (*blas)(int) = (void (*)(int))dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
    void (*omp)(int) = (void (*)(int))dlsym(RTLD_DEFAULT, "omp_set_num_threads");
    if (blas) {
        blas(n);
        ++found;
    }
    if (omp) {
        omp(n);
        ++found;
    }
    return found;
}
