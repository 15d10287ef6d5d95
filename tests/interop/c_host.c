/* A minimal FMI 2.0 Co-Simulation importer in C, with no Python of its
 * own (tests/interop/test_fmu_c_host.py): it loads an FMU's binary, runs
 * it from 0 to STOP in N equal steps and prints "t value" of one output per
 * communication point; every message the FMU logs goes to stderr.
 * Usage: c_host BINARY RESOURCE_URI GUID VALUE_REFERENCE STOP N */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

typedef void *Comp;
typedef void (*Logger)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    Logger logger;
    void *(*alloc)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *env;
} Callbacks;

typedef Comp (*Instantiate)(const char *, int, const char *, const char *, const Callbacks *,
                            int, int);
typedef int (*Setup)(Comp, int, double, double, int, double);
typedef int (*Call)(Comp);
typedef int (*DoStep)(Comp, double, double, int);
typedef int (*GetReal)(Comp, const unsigned *, size_t, double *);
typedef void (*Free)(Comp);

static void logger(void *env, const char *name, int status, const char *cat,
                   const char *fmt, ...) {
    (void)env;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "[%s %d %s] ", name, status, cat);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
}

#define SYM(type, name) type name = (type)dlsym(lib, #name); \
    if (!name) { fprintf(stderr, "missing %s\n", #name); return 2; }

int main(int argc, char **argv) {
    if (argc != 7)
        return 2;
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    SYM(Instantiate, fmi2Instantiate)
    SYM(Setup, fmi2SetupExperiment)
    SYM(Call, fmi2EnterInitializationMode)
    SYM(Call, fmi2ExitInitializationMode)
    SYM(DoStep, fmi2DoStep)
    SYM(GetReal, fmi2GetReal)
    SYM(Call, fmi2Terminate)
    SYM(Free, fmi2FreeInstance)
    Callbacks cb = {logger, calloc, free, NULL, NULL};
    unsigned vr = (unsigned)atoi(argv[4]);
    double stop = atof(argv[5]);
    int n = atoi(argv[6]);
    Comp c = fmi2Instantiate("host", 1, argv[3], argv[2], &cb, 0, 0);
    if (!c)
        return 3;
    if (fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, stop) || fmi2EnterInitializationMode(c) ||
        fmi2ExitInitializationMode(c))
        return 4;
    double h = stop / n, v;
    for (int k = 0; k < n; k++) {
        if (fmi2DoStep(c, k * h, h, 1) > 1)
            return 5;
        if (fmi2GetReal(c, &vr, 1, &v))
            return 6;
        printf("%.17g %.17g\n", (k + 1) * h, v);
    }
    fmi2Terminate(c);
    fmi2FreeInstance(c);
    return 0;
}
