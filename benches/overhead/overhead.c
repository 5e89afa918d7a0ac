/* Several FMU binaries stepped from C in one process, alternating, for `make bench-overhead`
 * and `make bench-percall` (scripts/bench_overhead.py and scripts/bench_percall.py write its
 * input and read its output).
 *
 *   overhead ROUNDS REPEATS DURATION STEP TOLERANCE [each] < cases
 *
 * stdin: one line per case, "LABEL LIBRARY GUID NR vr value ... NI vr value ... NG vr ...
 * NGI vr ...": the Real and Integer start values to set, then the Real and the Integer outputs
 * to read at the end. Each round runs every case REPEATS times in turn (fmi2Reset,
 * fmi2SetupExperiment with the tolerance, the start values, initialization, fmi2DoStep of STEP
 * up to DURATION; with `each`, fmi2GetReal of the Real outputs after every fmi2DoStep, as an
 * importer reads them). stdout: per round and case "time LABEL CPU_S" (process CPU of one
 * trajectory, the mean over the repeats), then per case "read LABEL value ..." (the Real ones
 * %.17g, then the Integer ones, at the last trajectory's end). */
#include "fmi2_calls.h"
#include <string.h>

typedef struct {
    char label[64];
    Component c;
    Setup setup;
    Call reset, enter, leave;
    SetReal set_real, get_real;
    SetInt set_int, get_int;
    DoStep step;
    size_t nr, ni, ng, ngi;
    unsigned rv[64], iv[64], gv[64], giv[64];
    double r[64], g[64];
    int i[64], gi[64];
} Case;

static int read_case(Case *k) {
    char lib_path[4096], guid[128];
    if (scanf("%63s %4095s %127s", k->label, lib_path, guid) != 3) return 0;
    if (scanf("%zu", &k->nr) != 1 || k->nr > 64) exit(2);
    for (size_t j = 0; j < k->nr; j++) if (scanf("%u %lf", &k->rv[j], &k->r[j]) != 2) exit(2);
    if (scanf("%zu", &k->ni) != 1 || k->ni > 64) exit(2);
    for (size_t j = 0; j < k->ni; j++) if (scanf("%u %d", &k->iv[j], &k->i[j]) != 2) exit(2);
    if (scanf("%zu", &k->ng) != 1 || k->ng > 64) exit(2);
    for (size_t j = 0; j < k->ng; j++) if (scanf("%u", &k->gv[j]) != 1) exit(2);
    if (scanf("%zu", &k->ngi) != 1 || k->ngi > 64) exit(2);
    for (size_t j = 0; j < k->ngi; j++) if (scanf("%u", &k->giv[j]) != 1) exit(2);
    void *lib = dlopen(lib_path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); exit(2); }
    static Callbacks cb = {logger, calloc, free, NULL, NULL};
    k->c = ((Instantiate)sym(lib, "fmi2Instantiate"))(k->label, 1, guid, "file:///tmp", &cb, 0, 0);
    if (!k->c) exit(2);
    k->setup = (Setup)sym(lib, "fmi2SetupExperiment");
    k->reset = (Call)sym(lib, "fmi2Reset");
    k->enter = (Call)sym(lib, "fmi2EnterInitializationMode");
    k->leave = (Call)sym(lib, "fmi2ExitInitializationMode");
    k->set_real = (SetReal)sym(lib, "fmi2SetReal");
    k->get_real = (SetReal)sym(lib, "fmi2GetReal");
    k->set_int = (SetInt)sym(lib, "fmi2SetInteger");
    k->get_int = (SetInt)sym(lib, "fmi2GetInteger");
    k->step = (DoStep)sym(lib, "fmi2DoStep");
    return 1;
}

/* One trajectory; the communication points are counted, not summed, so that every binary
 * sees the same times. */
static void run(Case *k, double duration, double h, double tol, int each) {
    long n = (long)(duration / h + 0.5);
    int bad = k->reset(k->c) || k->setup(k->c, 1, tol, 0.0, 1, duration)
              || k->set_real(k->c, k->rv, k->nr, k->r) || k->set_int(k->c, k->iv, k->ni, k->i)
              || k->enter(k->c) || k->leave(k->c);
    for (long j = 0; j < n && !bad; j++) {
        bad = k->step(k->c, j * h, h, 1);
        if (each && !bad) bad = k->get_real(k->c, k->gv, k->ng, k->g);
    }
    if (bad || k->get_real(k->c, k->gv, k->ng, k->g) || k->get_int(k->c, k->giv, k->ngi, k->gi)) {
        fprintf(stderr, "%s: refused\n", k->label);
        exit(1);
    }
}

int main(int argc, char **argv) {
    int each = argc == 7 && !strcmp(argv[6], "each");
    if (argc != 6 && !each) {
        fprintf(stderr, "usage: overhead ROUNDS REPEATS DURATION STEP TOLERANCE [each] < cases\n");
        return 2;
    }
    int rounds = atoi(argv[1]), repeats = atoi(argv[2]);
    double duration = atof(argv[3]), h = atof(argv[4]), tol = atof(argv[5]);
    static Case cases[16];
    int n = 0;
    while (n < 16 && read_case(&cases[n])) n++;
    for (int r = 0; r < rounds; r++) {
        for (int k = 0; k < n; k++) {
            double t0 = cpu();
            for (int j = 0; j < repeats; j++) run(&cases[k], duration, h, tol, each);
            printf("time %s %.9f\n", cases[k].label, (cpu() - t0) / repeats);
        }
    }
    for (int k = 0; k < n; k++) {
        printf("read %s", cases[k].label);
        for (size_t j = 0; j < cases[k].ng; j++) printf(" %.17g", cases[k].g[j]);
        for (size_t j = 0; j < cases[k].ngi; j++) printf(" %d", cases[k].gi[j]);
        printf("\n");
    }
    return 0;
}
