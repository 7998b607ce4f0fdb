/* Which kernels OpenBLAS runs, and a better choice where it does not know the CPU.
 *
 * OpenBLAS built for several CPUs (DYNAMIC_ARCH, as Debian ships it) picks its
 * kernels once, when it is loaded, from the CPU's family and model. OpenBLAS 0.3.21
 * (Debian 12) does not know CPUs newer than itself (Intel family 6 model 207, for
 * one) and then runs its generic SSE3 kernels ("Prescott"): on such a CPU they took
 * 0.61 of the time of its AVX-512 ones on ironing m4 N6 (docs/performance.md, "BLAS
 * kernels"). Later OpenBLAS versions choose by the CPU's features when they do not
 * know the model; voiga does the same, through OpenBLAS's own switch: the core type
 * variable OPENBLAS_CORETYPE read again by gotoblas_dynamic_init, before the first
 * BLAS call. A user's OPENBLAS_CORETYPE is left alone, and so is any other BLAS
 * (the functions are looked up with dlsym). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* The kernels to use instead of `detected`, given the CPU's features; NULL to keep
 * them. Only OpenBLAS's generic fallback is replaced. */
const char *voiga_kernels_for(const char *detected, int avx512, int avx2, int avx)
{
    if (detected == NULL || strcasecmp(detected, "Prescott") != 0)
        return NULL;
    if (avx512)
        return "SkylakeX";
    if (avx2)
        return "Haswell";
    if (avx)
        return "Sandybridge";
    return NULL;
}

static const char *corename(void)
{
    char *(*name)(void) = (char *(*)(void))dlsym(RTLD_DEFAULT, "openblas_get_corename");
    return name ? name() : NULL;
}

/* OpenBLAS's table of the kernels `name` (present only in builds that have them). */
static const char *table_of(const char *name)
{
    if (strcmp(name, "SkylakeX") == 0)
        return "gotoblas_SKYLAKEX";
    if (strcmp(name, "Haswell") == 0)
        return "gotoblas_HASWELL";
    return "gotoblas_SANDYBRIDGE";
}

/* Copy the name of the kernels in use into buf (at most len - 1 characters and a
 * terminating zero; "" when the BLAS is not OpenBLAS). */
void voiga_blas_kernels(char *buf, int len)
{
    const char *name = corename();
    if (len <= 0)
        return;
    buf[0] = '\0';
    if (name)
        strncat(buf, name, (size_t)len - 1);
}

/* Switch OpenBLAS to the kernels voiga_kernels_for chooses; call before any BLAS
 * call. Returns 1 when it switched, 0 when it left the kernels as they were. */
int voiga_choose_blas_kernels(void)
{
    void (*quit)(void) = (void (*)(void))dlsym(RTLD_DEFAULT, "gotoblas_dynamic_quit");
    void (*init)(void) = (void (*)(void))dlsym(RTLD_DEFAULT, "gotoblas_dynamic_init");
    const char *target;
    if (!quit || !init || getenv("OPENBLAS_CORETYPE") != NULL)
        return 0;
    __builtin_cpu_init();
    /* OpenBLAS's SkylakeX kernels use AVX-512 F, DQ, BW and VL; its Haswell ones AVX2
     * and FMA. GCC's feature test also checks that the OS saves the wide registers. */
    target = voiga_kernels_for(corename(),
                               __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                                   __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"),
                               __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"),
                               __builtin_cpu_supports("avx"));
    if (target == NULL || dlsym(RTLD_DEFAULT, table_of(target)) == NULL)
        return 0;
    if (setenv("OPENBLAS_CORETYPE", target, 1) != 0)
        return 0;
    quit();
    init();
    unsetenv("OPENBLAS_CORETYPE");
    return 1;
}
