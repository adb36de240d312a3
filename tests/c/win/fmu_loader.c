/*
 * Loads an FMU's Windows binary the way a Windows importer does (LoadLibrary and
 * GetProcAddress, no import library) and runs one co-simulation step:
 *
 *   fmu_loader DLL GUID RESOURCE_URI STEP [VR=VALUE ...] [?VR ...]
 *
 * fmi2GetVersion, fmi2Instantiate (logging on), fmi2SetupExperiment(t = 0),
 * fmi2EnterInitializationMode, fmi2ExitInitializationMode, fmi2SetReal of every VR=VALUE,
 * fmi2DoStep(0, STEP), fmi2GetReal of every ?VR (printed as "VR = VALUE" with 17 digits),
 * fmi2Terminate, fmi2FreeInstance. Exit status 0 when every call returns fmi2OK.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <windows.h>

#include "fmi2FunctionTypes.h"

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    char text[2048];
    va_list ap;
    (void)env;
    va_start(ap, message);
    vsnprintf(text, sizeof text, message, ap);
    va_end(ap);
    printf("log [%s %d %s] %s\n", instance, (int)status, category, text);
}

static HMODULE dll;

/* Function pointers pass through the generic `void (*)(void)` (ISO C allows casts between
 * function pointer types; this one is exempt from -Wcast-function-type). */
typedef void (*generic_fn)(void);

static generic_fn get(const char *name) {
    generic_fn f = (generic_fn)GetProcAddress(dll, name);
    if (f == NULL) {
        fprintf(stderr, "GetProcAddress(%s) failed\n", name);
        exit(1);
    }
    return f;
}

#define FN(name) name##TYPE *name = (name##TYPE *)get(#name)
#define OK(call)                                                            \
    do {                                                                    \
        fmi2Status s_ = (call);                                             \
        if (s_ != fmi2OK) {                                                 \
            fprintf(stderr, "%s returned status %d\n", #call, (int)s_);     \
            return 1;                                                       \
        }                                                                   \
    } while (0)

int main(int argc, char **argv) {
    if (argc < 5) {
        fprintf(stderr, "usage: %s DLL GUID RESOURCE_URI STEP [VR=VALUE ...] [?VR ...]\n",
                argv[0]);
        return 2;
    }
    dll = LoadLibraryA(argv[1]);
    if (dll == NULL) {
        fprintf(stderr, "LoadLibrary(%s) failed: error %lu\n", argv[1], GetLastError());
        return 1;
    }
    FN(fmi2GetVersion);
    FN(fmi2Instantiate);
    FN(fmi2SetupExperiment);
    FN(fmi2EnterInitializationMode);
    FN(fmi2ExitInitializationMode);
    FN(fmi2SetReal);
    FN(fmi2DoStep);
    FN(fmi2GetReal);
    FN(fmi2Terminate);
    FN(fmi2FreeInstance);
    double step = atof(argv[4]);

    printf("fmi2GetVersion = %s\n", fmi2GetVersion());
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c =
        fmi2Instantiate("win", fmi2CoSimulation, argv[2], argv[3], &cb, fmi2False, fmi2True);
    if (c == NULL) {
        fprintf(stderr, "fmi2Instantiate failed\n");
        return 1;
    }
    OK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    OK(fmi2EnterInitializationMode(c));
    OK(fmi2ExitInitializationMode(c));
    for (int i = 5; i < argc; i++) {
        unsigned vr;
        double value;
        if (sscanf(argv[i], "%u=%lf", &vr, &value) == 2) {
            fmi2ValueReference r = vr;
            OK(fmi2SetReal(c, &r, 1, &value));
        }
    }
    OK(fmi2DoStep(c, 0.0, step, fmi2True));
    for (int i = 5; i < argc; i++) {
        unsigned vr;
        if (sscanf(argv[i], "?%u", &vr) == 1) {
            fmi2ValueReference r = vr;
            double value;
            OK(fmi2GetReal(c, &r, 1, &value));
            printf("%u = %.17g\n", vr, value);
        }
    }
    OK(fmi2Terminate(c));
    fmi2FreeInstance(c);
    FreeLibrary(dll);
    printf("fmu_loader: done\n");
    return 0;
}
