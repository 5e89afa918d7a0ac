/* The FMI 2.0 co-simulation calls the C harnesses use (step_points.c beside this file, the
 * overhead benchmark benches/overhead/overhead.c): their types, a logger to stderr, a symbol
 * looked up or the process ended, the process's CPU time. */
#ifndef FMI2_CALLS_H
#define FMI2_CALLS_H
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

static double cpu(void) {
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

#endif
