/*
 * Cost of one hgm_evaluate call (Table 1, default options) over one mesh period at a static
 * TE of 31 µm, the states a drivetrain simulation visits. Not a test; see docs/c-api.md.
 *
 *   gcc -O2 -Iinclude tests/c/bench_capi.c -Ltarget/release -lhelical_gear_mesh \
 *       -Wl,-rpath,$PWD/target/release -o /tmp/bench_capi && /tmp/bench_capi
 */
#include <stdio.h>
#include <time.h>

#include "helical_gear_mesh.h"

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(void) {
    const double g_p = 0.042860629350090065, g_g = 0.06714831931514112, te = 31e-6;
    const double pitch = 2.0 * 3.141592653589793 / 30.0;
    const int n = 2000;
    HgmModel *m = hgm_create_default();
    if (m == NULL) {
        fprintf(stderr, "%s\n", hgm_last_error(NULL));
        return 1;
    }
    HgmOutputs out;
    double sum = 0.0;
    for (int rep = 0; rep < 2; rep++) { /* first pass warms up */
        double t0 = now();
        for (int k = 0; k < n; k++) {
            double phi_p = pitch * k / n;
            if (hgm_evaluate(m, phi_p, (te - phi_p * g_p) / g_g, 100.0, -63.83, &out)) {
                fprintf(stderr, "%s\n", hgm_last_error(m));
                return 1;
            }
            sum += out.m_f_p;
        }
        double dt = now() - t0;
        if (rep == 1)
            printf("hgm_evaluate: %.1f us per call (%d calls, mean M_F_p %.3f N.m)\n",
                   1e6 * dt / n, n, sum / (2.0 * n));
    }
    hgm_free(m);
    return 0;
}
