/* Steps an FMU's binary as an FMI 2.0 importer does, without any FMI library: load it
 * (LoadLibrary on Windows, dlopen elsewhere), instantiate with the GUID given, set
 * excitation = 1 (GearRattle: the sine mode, the other parameters keep their defaults: scene
 * S1 of the paper; GearboxRattle: the built-in engine at idle), step to t_end with fixed
 * communication steps, print xi and the impact counters (GearboxRattle: gear 1's).
 *
 * Built twice by tests/windows/run.sh from this one file: with MinGW-w64 for the win64 DLL
 * (run under Wine) and with gcc for the linux64 .so, so that both binaries of the FMU are
 * driven by the same code and their results can be compared.
 *
 * Usage: fmu_run LIBRARY GUID T_END DT [VR_G VR_XI VR_EXCITATION VR_IMPACTS_FPLUS VR_IMPACTS_FMINUS]
 * (the value references of those variables; GearRattle's by default)
 * Output (one line): xi=<%.17g> G=<%.17g> impacts_Fplus=<n> impacts_Fminus=<n> steps=<n>
 * Exit status: 0, or 1 as soon as a call does not answer fmi2OK (the reason on stderr). */

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE Library;
static Library open_library(const char *path) { return LoadLibraryA(path); }
static void *symbol(Library lib, const char *name) { return (void *)GetProcAddress(lib, name); }
static void library_error(const char *path) {
    fprintf(stderr, "LoadLibrary(%s) failed: error %lu\n", path, (unsigned long)GetLastError());
}
#else
#include <dlfcn.h>
typedef void *Library;
static Library open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(Library lib, const char *name) { return dlsym(lib, name); }
static void library_error(const char *path) { fprintf(stderr, "dlopen(%s) failed: %s\n", path, dlerror()); }
#endif

/* The few FMI 2.0 types used (fmi2TypesPlatform.h, fmi2FunctionTypes.h). */
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef const char *fmi2String;
typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef struct {
    void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

typedef fmi2Component (*Instantiate)(fmi2String, fmi2Type, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
typedef fmi2Status (*Call)(fmi2Component);
typedef fmi2Status (*SetInteger)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Integer *);
typedef fmi2Status (*GetInteger)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Integer *);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef void (*FreeInstance)(fmi2Component);

/* Value references (modelDescription/GearRattle.toml). */
/* GearRattle's value references of G, xi, excitation, impacts_Fplus, impacts_Fminus. */
enum { VR_G, VR_XI, VR_EXCITATION, VR_IMPACTS_FPLUS, VR_IMPACTS_FMINUS, VRS };
static fmi2ValueReference vrs[VRS] = {7, 34, 100, 102, 103};

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list args;
    (void)env;
    fprintf(stderr, "[%s] %s (status %d): ", instance ? instance : "?", category ? category : "?", (int)status);
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fputc('\n', stderr);
}

static Library lib;

static void *need(const char *name) {
    void *f = symbol(lib, name);
    if (!f) {
        fprintf(stderr, "%s is not exported\n", name);
        exit(1);
    }
    return f;
}

static void check(fmi2Status status, const char *call) {
    if (status != fmi2OK) {
        fprintf(stderr, "%s returned status %d, not fmi2OK\n", call, (int)status);
        exit(1);
    }
}

int main(int argc, char **argv) {
    if (argc != 5 && argc != 5 + VRS) {
        fprintf(stderr, "usage: %s LIBRARY GUID T_END DT [VR_G VR_XI VR_EXCITATION VR_IMPACTS_FPLUS VR_IMPACTS_FMINUS]\n",
                argv[0]);
        return 2;
    }
    for (int k = 0; argc == 5 + VRS && k < VRS; k++) {
        vrs[k] = (fmi2ValueReference)strtoul(argv[5 + k], NULL, 10);
    }
    const char *path = argv[1], *guid = argv[2];
    double t_end = atof(argv[3]), dt = atof(argv[4]);
    long steps = (long)(t_end / dt + 0.5);
    if (!(dt > 0) || steps < 1) {
        fprintf(stderr, "T_END and DT must be positive (got %s, %s)\n", argv[3], argv[4]);
        return 2;
    }

    lib = open_library(path);
    if (!lib) {
        library_error(path);
        return 1;
    }
    Instantiate instantiate = (Instantiate)need("fmi2Instantiate");
    SetupExperiment setup = (SetupExperiment)need("fmi2SetupExperiment");
    Call enter_init = (Call)need("fmi2EnterInitializationMode");
    Call exit_init = (Call)need("fmi2ExitInitializationMode");
    Call terminate = (Call)need("fmi2Terminate");
    SetInteger set_integer = (SetInteger)need("fmi2SetInteger");
    GetInteger get_integer = (GetInteger)need("fmi2GetInteger");
    GetReal get_real = (GetReal)need("fmi2GetReal");
    DoStep do_step = (DoStep)need("fmi2DoStep");
    FreeInstance free_instance = (FreeInstance)need("fmi2FreeInstance");

    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("fmu_run", fmi2CoSimulation, guid, NULL, &callbacks, 0, 0);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate returned NULL (GUID %s)\n", guid);
        return 1;
    }
    const fmi2ValueReference excitation_vr = vrs[VR_EXCITATION];
    const fmi2Integer sine = 1;
    check(set_integer(c, &excitation_vr, 1, &sine), "fmi2SetInteger(excitation)");
    check(setup(c, 0, 0.0, 0.0, 1, t_end), "fmi2SetupExperiment");
    check(enter_init(c), "fmi2EnterInitializationMode");
    check(exit_init(c), "fmi2ExitInitializationMode");

    for (long i = 0; i < steps; i++) {
        check(do_step(c, i * dt, dt, 1), "fmi2DoStep");
    }

    const fmi2ValueReference real_vrs[2] = {vrs[VR_XI], vrs[VR_G]};
    const fmi2ValueReference int_vrs[2] = {vrs[VR_IMPACTS_FPLUS], vrs[VR_IMPACTS_FMINUS]};
    fmi2Real reals[2];
    fmi2Integer ints[2];
    check(get_real(c, real_vrs, 2, reals), "fmi2GetReal");
    check(get_integer(c, int_vrs, 2, ints), "fmi2GetInteger");
    check(terminate(c), "fmi2Terminate");
    free_instance(c);

    printf("xi=%.17g G=%.17g impacts_Fplus=%d impacts_Fminus=%d steps=%ld\n", reals[0], reals[1],
           ints[0], ints[1], steps);
    return 0;
}
