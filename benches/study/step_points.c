/* The FMU stepped from C alone, for the study benchmark (benches/study/study_bench.py):
 * one instance, and per point what the study runner does (fmi2Reset, fmi2SetupExperiment, the
 * start values, initialization, one fmi2DoStep over the duration, the outputs read).
 *
 *   step_points LIBRARY GUID RESOURCE_URI < points
 *
 * stdin: the value references to set (Real, then Integer) and to read (Real, then Integer),
 * each line "COUNT vr vr ...", then the duration, then one line of values per point (Real
 * ones, then Integer ones). stdout: one line per point with the values read, then
 * "cpu_s TOTAL" (process CPU time of the points, instantiation excluded). */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef void *Component;
typedef void (*Logger)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    Logger logger;
    void *(*allocate)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *env;
} Callbacks;
typedef Component (*Instantiate)(const char *, int, const char *, const char *,
                                 const Callbacks *, int, int);
typedef int (*Setup)(Component, int, double, double, int, double);
typedef int (*Call)(Component);
typedef int (*SetReal)(Component, const unsigned *, size_t, const double *);
typedef int (*SetInt)(Component, const unsigned *, size_t, const int *);
typedef int (*DoStep)(Component, double, double, int);

static void logger(void *env, const char *name, int status, const char *cat, const char *msg,
                   ...) {
    (void)env; (void)cat;
    va_list ap;
    va_start(ap, msg);
    fprintf(stderr, "%s [%d]: ", name, status);
    vfprintf(stderr, msg, ap);
    fputc('\n', stderr);
    va_end(ap);
}

static void *sym(void *lib, const char *name) {
    void *f = dlsym(lib, name);
    if (!f) { fprintf(stderr, "missing %s\n", name); exit(2); }
    return f;
}

static unsigned *read_vrs(size_t *n) {
    if (scanf("%zu", n) != 1) exit(2);
    unsigned *v = malloc((*n + 1) * sizeof *v);
    for (size_t i = 0; i < *n; i++) if (scanf("%u", &v[i]) != 1) exit(2);
    return v;
}

static double cpu(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

int main(int argc, char **argv) {
    if (argc != 4) { fprintf(stderr, "usage: step_points LIBRARY GUID RESOURCE_URI\n"); return 2; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); return 2; }
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    Component c = ((Instantiate)sym(lib, "fmi2Instantiate"))("c", 1, argv[2], argv[3], &cb, 0, 0);
    if (!c) return 2;
    Setup setup = (Setup)sym(lib, "fmi2SetupExperiment");
    Call reset = (Call)sym(lib, "fmi2Reset"), enter = (Call)sym(lib, "fmi2EnterInitializationMode"),
         leave = (Call)sym(lib, "fmi2ExitInitializationMode");
    SetReal set_real = (SetReal)sym(lib, "fmi2SetReal"), get_real = (SetReal)sym(lib, "fmi2GetReal");
    SetInt set_int = (SetInt)sym(lib, "fmi2SetInteger"), get_int = (SetInt)sym(lib, "fmi2GetInteger");
    DoStep step = (DoStep)sym(lib, "fmi2DoStep");
    size_t nsr, nsi, ngr, ngi;
    unsigned *sr = read_vrs(&nsr), *si = read_vrs(&nsi), *gr = read_vrs(&ngr), *gi = read_vrs(&ngi);
    double duration;
    if (scanf("%lf", &duration) != 1) return 2;
    double *vr = malloc((nsr + 1) * sizeof *vr), *outr = malloc((ngr + 1) * sizeof *outr);
    int *vi = malloc((nsi + 1) * sizeof *vi), *outi = malloc((ngi + 1) * sizeof *outi);
    double total = 0;
    for (int first = 1;; first = 0) {
        for (size_t i = 0; i < nsr; i++) if (scanf("%lf", &vr[i]) != 1) goto done;
        for (size_t i = 0; i < nsi; i++) if (scanf("%d", &vi[i]) != 1) goto done;
        double t0 = cpu();
        int bad = (!first && reset(c)) || setup(c, 0, 0.0, 0.0, 1, duration)
                  || set_real(c, sr, nsr, vr) || set_int(c, si, nsi, vi) || enter(c) || leave(c)
                  || step(c, 0.0, duration, 1) || get_real(c, gr, ngr, outr)
                  || get_int(c, gi, ngi, outi);
        total += cpu() - t0;
        if (bad) { printf("refused\n"); continue; }
        for (size_t i = 0; i < ngr; i++) printf("%.17g ", outr[i]);
        for (size_t i = 0; i < ngi; i++) printf("%d ", outi[i]);
        printf("\n");
    }
done:
    printf("cpu_s %.9f\n", total);
    return 0;
}
