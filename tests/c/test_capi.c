/*
 * C test of the library's two C interfaces, compiled with gcc -Wall -Wextra -Werror against
 * the generated headers:
 *
 *   include/helical_gear_mesh.h        the plain C API (hgm_*)
 *   include/helical_gear_mesh_fmi2.h   the exported fmi2* functions; it includes the FMI 2.0
 *                                      standard's fmi2Functions.h, so the compiler checks every
 *                                      exported signature against the standard's declaration
 *
 * Usage: test_capi GUID [REPEAT]   (the FMU's GUID from modelDescription.xml; REPEAT is the
 * number of create/free and instantiate/free cycles of the stress part, default 1000)
 * Exit status 0 when every check passes; each failed check is printed.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helical_gear_mesh.h"
#include "helical_gear_mesh_fmi2.h"
#include "fmi2_models/HelicalGearDrive.h"
#include "fmi2_models/HelicalGearMesh.h"

static int failures = 0;

#define CHECK(cond, ...)                                                 \
    do {                                                                 \
        if (!(cond)) {                                                   \
            failures++;                                                  \
            fprintf(stderr, "FAILED %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                \
            fprintf(stderr, "\n");                                       \
        }                                                                \
    } while (0)

/* Table 1 base radii (m), for setting a transmission error TE = phi_p*g_p + phi_g*g_g. */
static const double G_P = 0.042860629350090065;
static const double G_G = 0.06714831931514112;

static double phi_g_for(double phi_p, double te) { return (te - phi_p * G_P) / G_G; }

/* ------------------------------------------------------------------ plain C API */

static void test_capi(void) {
    HgmOutputs out;

    /* Error paths that need no model. */
    CHECK(hgm_evaluate(NULL, 0, 0, 0, 0, &out) == HGM_STATUS_INVALID_ARGUMENT, "NULL handle");
    CHECK(strstr(hgm_last_error(NULL), "NULL") != NULL, "message: %s", hgm_last_error(NULL));
    CHECK(hgm_create_from_json(NULL) == NULL, "NULL json");
    CHECK(hgm_create_from_json("{ not json") == NULL, "malformed json");
    CHECK(strstr(hgm_last_error(NULL), "JSON") != NULL, "message: %s", hgm_last_error(NULL));
    CHECK(hgm_create_from_json("{\"z_p\": 30, \"colour\": 1}") == NULL, "unknown key");
    CHECK(strstr(hgm_last_error(NULL), "colour") != NULL, "message: %s", hgm_last_error(NULL));
    {
        const char *bad =
            "{\"z_p\": 12, \"z_g\": 47, \"normal_module_m\": 0.003,"
            " \"pressure_angle_rad\": 0.3490658503988659, \"helix_angle_rad\": 0.17453292519943295,"
            " \"face_width_m\": 0.015, \"addendum_mn\": 1.0, \"dedendum_mn\": 1.25,"
            " \"rack_fillet_radius_mn\": 0.35, \"tip_relief_depth_mn\": 0.015,"
            " \"tip_relief_height_mn\": 0.5, \"tip_rounding_radius_mn\": 0.05,"
            " \"normal_backlash_mn\": 0.0725, \"bore_diameter_m\": 0.015,"
            " \"material_p\": {\"youngs_modulus_pa\": 206e9, \"poisson_ratio\": 0.3,"
            " \"density_kg_m3\": 7850.0},"
            " \"material_g\": {\"youngs_modulus_pa\": 206e9, \"poisson_ratio\": 0.3,"
            " \"density_kg_m3\": 7850.0},"
            " \"d_mesh_n_s_per_m\": 100.0}";
        CHECK(hgm_create_from_json(bad) == NULL, "z_p = 12 is below the undercut limit");
        CHECK(strstr(hgm_last_error(NULL), "`z_p` = 12") != NULL, "message: %s",
              hgm_last_error(NULL));
    }
    /* The drive line is not part of the gear pair: a pair with `drive` is refused with a
       message that says where it goes now. */
    CHECK(hgm_create_from_json("{\"drive\": {\"torque_nm\": 50}}") == NULL, "pair with drive");
    CHECK(strstr(hgm_last_error(NULL), "drive_json") != NULL, "message: %s",
          hgm_last_error(NULL));
    CHECK(hgm_unit_create(HGM_UNIT_KIND_DRIVE, "{\"drive\": {}}", NULL, HGM_FIDELITY_FULL, 128,
                          0, 0) == NULL,
          "unit pair with drive");
    CHECK(strstr(hgm_unit_last_error(NULL), "drive_json") != NULL, "message: %s",
          hgm_unit_last_error(NULL));
    /* A drive line with an unknown key, or not an object, is refused naming it. */
    CHECK(hgm_unit_create(HGM_UNIT_KIND_DRIVE, NULL, "{\"torque\": 1}", HGM_FIDELITY_FULL, 128,
                          0, 0) == NULL,
          "drive line with an unknown key");
    CHECK(strstr(hgm_unit_last_error(NULL), "torque") != NULL, "message: %s",
          hgm_unit_last_error(NULL));
    CHECK(hgm_unit_create(HGM_UNIT_KIND_DRIVE, NULL, "[]", HGM_FIDELITY_FULL, 128, 0, 0) == NULL,
          "drive line []");
    CHECK(strstr(hgm_unit_last_error(NULL), "must be an object") != NULL, "message: %s",
          hgm_unit_last_error(NULL));
    hgm_free(NULL);

    HgmModel *m = hgm_create_default();
    CHECK(m != NULL, "default model: %s", hgm_last_error(NULL));
    if (m == NULL) return;
    CHECK(strcmp(hgm_last_error(m), "") == 0, "no error yet");

    /* Static equilibrium at phi_p = 0 with the Table 1 torque of 100 N.m: bisection on TE. */
    double lo = 0.0, hi = 200e-6;
    for (int i = 0; i < 50; i++) {
        double te = 0.5 * (lo + hi);
        CHECK(hgm_evaluate(m, 0.0, phi_g_for(0.0, te), 0, 0, &out) == HGM_STATUS_OK, "%s",
              hgm_last_error(m));
        if (out.m_f_p < 100.0) lo = te; else hi = te;
    }
    double te_static = 0.5 * (lo + hi);
    printf("static TE at phi_p = 0 under 100 N.m: %.4f um (M_F_g = %.3f N.m, %u pairs)\n",
           te_static * 1e6, out.m_f_g, out.n_pairs);
    CHECK(te_static > 10e-6 && te_static < 60e-6, "static TE %g m (paper: max 30.5 um)",
          te_static);
    CHECK(fabs(out.te - te_static) < 1e-9, "TE output %g", out.te);
    CHECK(fabs(out.m_f_g / out.m_f_p - G_G / G_P) < 0.05 * G_G / G_P,
          "M_F_g/M_F_p = %g, g_g/g_p = %g", out.m_f_g / out.m_f_p, G_G / G_P);
    CHECK(out.f_n > 0 && out.contact_length > 0 && out.p_max > 1e8, "load diagnostics");
    CHECK(!out.separated && !out.back_contact && out.n_pairs >= 1, "flags");

    /* Rolling at 100 rad/s with the teeth approaching: the damping torque opposes it. */
    double w_p = 100.0, w_g = -100.0 * 30.0 / 47.0 + 0.01;
    CHECK(hgm_evaluate(m, 0.0, phi_g_for(0.0, te_static), w_p, w_g, &out) == HGM_STATUS_OK,
          "%s", hgm_last_error(m));
    CHECK(out.m_d_p * (w_p * G_P + w_g * G_G) > 0, "M_D_p = %g has the sign of dTE/dt", out.m_d_p);
    CHECK(hgm_set_d_mesh(m, 0.0) == HGM_STATUS_OK, "%s", hgm_last_error(m));
    CHECK(hgm_evaluate(m, 0.0, phi_g_for(0.0, te_static), w_p, w_g, &out) == HGM_STATUS_OK, "%s", hgm_last_error(m));
    CHECK(out.m_d_p == 0.0, "no damping torque with d_mesh = 0: %g", out.m_d_p);

    /* Inside the backlash: separated; beyond it: back flanks, negative torque. */
    CHECK(hgm_evaluate(m, 0.0, phi_g_for(0.0, -10e-6), 0, 0, &out) == HGM_STATUS_OK, "%s", hgm_last_error(m));
    CHECK(out.separated && out.m_f_p == 0.0 && out.n_pairs == 0, "separated at TE = -10 um");
    CHECK(hgm_evaluate(m, 0.0, phi_g_for(0.0, -240e-6), 0, 0, &out) == HGM_STATUS_OK, "%s",
          hgm_last_error(m));
    CHECK(out.back_contact && out.m_f_p < 0.0, "back contact at TE = -240 um: M_F_p = %g",
          out.m_f_p);

    /* Only the outputs read (hgm_evaluate_outputs): the values of hgm_evaluate. At full
     * fidelity both start from the handle's warm start, so they agree to the solver's
     * tolerance; at table fidelity bit for bit, on the torques path (only torques outputs
     * requested) and on the complete one. */
    {
        int32_t k_mfp = hgm_output_index("M_F_p"), k_te = hgm_output_index("TE");
        int32_t k_fn = hgm_output_index("F_n"), k_np = hgm_output_index("n_pairs");
        int32_t k_sep = hgm_output_index("separated");
        CHECK(k_mfp == 0 && k_te == 4 && k_fn == 5 && k_np == 8 && k_sep == 10,
              "indices %d %d %d %d %d", k_mfp, k_te, k_fn, k_np, k_sep);
        CHECK(hgm_output_index("Q_g") == HGM_N_OUTPUTS - 1, "Q_g is the last output");
        CHECK(hgm_output_index("colour") == -1, "unknown name");
        CHECK(strstr(hgm_last_error(NULL), "`colour`") != NULL &&
                  strstr(hgm_last_error(NULL), "M_F_p") != NULL,
              "message: %s", hgm_last_error(NULL));
        CHECK(hgm_output_index(NULL) == -1, "NULL name");
        double phi_g = phi_g_for(0.0, te_static);
        HgmOutputs all;
        CHECK(hgm_evaluate(m, 0.0, phi_g, w_p, w_g, &all) == HGM_STATUS_OK, "%s",
              hgm_last_error(m));
        uint32_t torques[3] = {(uint32_t)k_te, (uint32_t)k_mfp, (uint32_t)k_mfp};
        double v[4] = {-1, -1, -1, -1};
        CHECK(hgm_evaluate_outputs(m, 0.0, phi_g, w_p, w_g, torques, 3, v) == HGM_STATUS_OK,
              "%s", hgm_last_error(m));
        CHECK(v[0] == all.te && fabs(v[1] - all.m_f_p) < 1e-9 * fabs(all.m_f_p) &&
                  v[2] == v[1] && v[3] == -1,
              "full: %g %g %g %g vs %g %g", v[0], v[1], v[2], v[3], all.te, all.m_f_p);
        uint32_t mixed[3] = {(uint32_t)k_fn, (uint32_t)k_np, (uint32_t)k_sep};
        CHECK(hgm_evaluate_outputs(m, 0.0, phi_g, w_p, w_g, mixed, 3, v) == HGM_STATUS_OK,
              "%s", hgm_last_error(m));
        CHECK(fabs(v[0] - all.f_n) < 1e-9 * all.f_n && v[1] == (double)all.n_pairs &&
                  v[2] == (all.separated ? 1.0 : 0.0),
              "full, mixed: %g %g %g", v[0], v[1], v[2]);
        /* Refused, naming the argument; `values` left as it was. */
        uint32_t beyond[2] = {(uint32_t)k_te, HGM_N_OUTPUTS};
        v[0] = -1;
        CHECK(hgm_evaluate_outputs(m, 0.0, phi_g, w_p, w_g, beyond, 2, v) ==
                  HGM_STATUS_INVALID_ARGUMENT, "index HGM_N_OUTPUTS");
        CHECK(strstr(hgm_last_error(m), "`fields[1]` = 30") != NULL && v[0] == -1,
              "message: %s", hgm_last_error(m));
        CHECK(hgm_evaluate_outputs(m, 0.0, phi_g, w_p, w_g, torques, 1, NULL) ==
                  HGM_STATUS_INVALID_ARGUMENT, "NULL values");
        CHECK(strstr(hgm_last_error(m), "`values` is NULL") != NULL, "message: %s",
              hgm_last_error(m));
        CHECK(hgm_evaluate_outputs(m, 0.0, phi_g, w_p, w_g, NULL, 0, NULL) == HGM_STATUS_OK,
              "no output requested: %s", hgm_last_error(m));
        CHECK(hgm_evaluate_outputs(m, 0.0, phi_g, w_p, w_g, torques, 100000, v) ==
                  HGM_STATUS_INVALID_ARGUMENT, "n_fields beyond its bound");
        CHECK(strstr(hgm_last_error(m), "<= 1024") != NULL, "message: %s", hgm_last_error(m));
        CHECK(hgm_evaluate_outputs(m, NAN, phi_g, w_p, w_g, torques, 1, v) ==
                  HGM_STATUS_INVALID_ARGUMENT, "NaN input");

        CHECK(hgm_create(NULL, 7) == NULL, "fidelity 7");
        CHECK(strstr(hgm_last_error(NULL), "`fidelity` = 7") != NULL, "message: %s",
              hgm_last_error(NULL));
        /* A table-fidelity model builds its table (skipped with the units under valgrind). */
        const char *skip = getenv("HGM_TEST_SKIP_UNITS");
        HgmModel *t = skip && strcmp(skip, "1") == 0 ? NULL : hgm_create(NULL, HGM_FIDELITY_TABLE);
        CHECK(t != NULL || skip != NULL, "table model: %s", hgm_last_error(NULL));
        if (t != NULL) {
            for (int i = 0; i < 8; i++) {
                double phi_p = 0.013 * i, te = (5.0 + 7.0 * i) * 1e-6;
                double pg = phi_g_for(phi_p, te);
                CHECK(hgm_evaluate(t, phi_p, pg, w_p, w_g, &all) == HGM_STATUS_OK, "%s",
                      hgm_last_error(t));
                uint32_t set[5] = {0, 1, 2, 3, (uint32_t)k_te};
                double u[5];
                CHECK(hgm_evaluate_outputs(t, phi_p, pg, w_p, w_g, set, 5, u) == HGM_STATUS_OK,
                      "%s", hgm_last_error(t));
                CHECK(u[0] == all.m_f_p && u[1] == all.m_f_g && u[2] == all.m_d_p &&
                          u[3] == all.m_d_g && u[4] == all.te,
                      "table, torques path at %d: %g vs %g", i, u[0], all.m_f_p);
                CHECK(hgm_evaluate_outputs(t, phi_p, pg, w_p, w_g, mixed, 3, u) ==
                          HGM_STATUS_OK, "%s", hgm_last_error(t));
                CHECK(u[0] == all.f_n && u[1] == (double)all.n_pairs, "table, complete at %d", i);
            }
            hgm_free(t);
        }
    }

    /* Error paths with a model: the handle stays usable. */
    CHECK(hgm_evaluate(m, NAN, 0, 0, 0, &out) == HGM_STATUS_INVALID_ARGUMENT, "NaN input");
    CHECK(strstr(hgm_last_error(m), "`phi_p` = NaN") != NULL, "message: %s", hgm_last_error(m));
    CHECK(hgm_evaluate(m, 0, 0, INFINITY, 0, &out) == HGM_STATUS_INVALID_ARGUMENT, "inf input");
    CHECK(strstr(hgm_last_error(m), "`w_p` = inf") != NULL, "message: %s", hgm_last_error(m));
    CHECK(hgm_evaluate(m, 0, 0, 0, 0, NULL) == HGM_STATUS_INVALID_ARGUMENT, "NULL out");
    CHECK(hgm_set_d_mesh(m, -1.0) == HGM_STATUS_MODEL_ERROR, "negative d_mesh");
    CHECK(strstr(hgm_last_error(m), "d_mesh") != NULL, "message: %s", hgm_last_error(m));
    CHECK(hgm_set_d_mesh(m, 1e300) == HGM_STATUS_MODEL_ERROR, "d_mesh beyond its range");
    CHECK(strstr(hgm_last_error(m), "1.0000e300") != NULL, "short number: %s",
          hgm_last_error(m));
    CHECK(hgm_evaluate(m, 0.0, phi_g_for(0.0, te_static), 0, 0, &out) == HGM_STATUS_OK,
          "usable after errors");
    hgm_free(m);
}

/* ------------------------------------------------------------------ stateful units */

static void test_units(void) {
    CHECK(hgm_unit_advance(NULL, 1e-4) == HGM_STATUS_INVALID_ARGUMENT, "NULL unit");
    CHECK(strstr(hgm_unit_last_error(NULL), "NULL") != NULL, "message: %s",
          hgm_unit_last_error(NULL));
    CHECK(hgm_unit_create(HGM_UNIT_KIND_STAGE, NULL, NULL, HGM_FIDELITY_TABLE, 2, 0, 0) == NULL,
          "too few steps per mesh period");
    CHECK(strstr(hgm_unit_last_error(NULL), "steps_per_mesh_period") != NULL, "message: %s",
          hgm_unit_last_error(NULL));
    /* The enum arguments are integers checked against their allowed values. */
    CHECK(hgm_unit_create(3, NULL, NULL, HGM_FIDELITY_TABLE, 128, 0, 0) == NULL, "kind 3");
    CHECK(strstr(hgm_unit_last_error(NULL), "`kind` = 3") != NULL, "message: %s",
          hgm_unit_last_error(NULL));
    CHECK(hgm_unit_create(HGM_UNIT_KIND_PAIR, NULL, NULL, -1, 128, 0, 0) == NULL, "fidelity -1");
    CHECK(strstr(hgm_unit_last_error(NULL), "`fidelity` = -1") != NULL, "message: %s",
          hgm_unit_last_error(NULL));
    hgm_unit_free(NULL);

    /* The whole drive at 532 rad/s from its static equilibrium. */
    /* A partial drive line (missing keys from Table 1): the static start carries its torque. */
    HgmUnit *h = hgm_unit_create(HGM_UNIT_KIND_DRIVE, NULL, "{\"torque_nm\": 50}",
                                 HGM_FIDELITY_FULL, 128, 0, 0);
    CHECK(h != NULL, "drive unit at 50 N.m: %s", hgm_unit_last_error(NULL));
    if (h != NULL) {
        CHECK(hgm_unit_start_static(h, 0.0, 532.0) == HGM_STATUS_OK, "%s",
              hgm_unit_last_error(h));
        HgmUnitOutputs oh;
        CHECK(hgm_unit_outputs(h, &oh) == HGM_STATUS_OK, "%s", hgm_unit_last_error(h));
        CHECK(fabs(oh.tau_1 + 50.0) < 0.5, "static start at 50 N.m: tau_1 %g", oh.tau_1);
        hgm_unit_free(h);
    }

    HgmUnit *u = hgm_unit_create(HGM_UNIT_KIND_DRIVE, NULL, NULL, HGM_FIDELITY_TABLE, 128, 0, 0);
    CHECK(u != NULL, "drive unit: %s", hgm_unit_last_error(NULL));
    CHECK(hgm_unit_start_static(u, 0.0, 532.0) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    HgmUnitOutputs out;
    CHECK(hgm_unit_outputs(u, &out) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    CHECK(out.mesh.te > 0.0 && fabs(out.tau_1 + 100.0) < 1.0, "static start: TE %g, tau_1 %g",
          out.mesh.te, out.tau_1);
    for (int i = 0; i < 20; i++) {
        CHECK(hgm_unit_advance(u, 1e-4) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    }
    const char *snap = hgm_unit_snapshot(u);
    CHECK(snap != NULL, "%s", hgm_unit_last_error(u));
    char saved[4096];
    CHECK(strlen(snap) < sizeof saved, "snapshot length");
    strcpy(saved, snap);
    CHECK(hgm_unit_advance(u, 3e-4) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    HgmUnitOutputs a, b;
    CHECK(hgm_unit_outputs(u, &a) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    CHECK(fabs(a.t - 2.3e-3) < 1e-12 && a.w_p > 500.0 && a.w_p < 560.0, "t %g, w_p %g", a.t,
          a.w_p);
    CHECK(hgm_unit_restore(u, saved) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    CHECK(hgm_unit_advance(u, 3e-4) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    CHECK(hgm_unit_outputs(u, &b) == HGM_STATUS_OK, "%s", hgm_unit_last_error(u));
    CHECK(a.mesh.te == b.mesh.te && a.phi_p == b.phi_p, "restore: TE %.17g vs %.17g",
          a.mesh.te, b.mesh.te);

    /* Errors leave the unit usable. */
    CHECK(hgm_unit_advance(u, -1.0) == HGM_STATUS_INVALID_ARGUMENT, "negative step");
    CHECK(strstr(hgm_unit_last_error(u), "`h` = -1") != NULL, "message: %s",
          hgm_unit_last_error(u));
    HgmUnitInputs in = {0};
    in.torque = NAN;
    CHECK(hgm_unit_set_inputs(u, &in) == HGM_STATUS_INVALID_ARGUMENT, "NaN torque");
    CHECK(strstr(hgm_unit_last_error(u), "torque") != NULL, "message: %s",
          hgm_unit_last_error(u));
    CHECK(hgm_unit_restore(u, "{ not json") == HGM_STATUS_INVALID_ARGUMENT, "bad snapshot");
    CHECK(hgm_unit_outputs(u, NULL) == HGM_STATUS_INVALID_ARGUMENT, "NULL out");
    CHECK(hgm_unit_advance(u, 1e-4) == HGM_STATUS_OK, "usable after errors: %s",
          hgm_unit_last_error(u));
    /* The hub coupling is the Pair's alone. */
    CHECK(hgm_unit_set_hub_coupling(u, 984.0, 0.04, 984.0, 0.04) == HGM_STATUS_INVALID_ARGUMENT,
          "coupling on a drive unit");
    CHECK(strstr(hgm_unit_last_error(u), "hub coupling") != NULL, "message: %s",
          hgm_unit_last_error(u));
    hgm_unit_free(u);

    /* A Pair with input rates and the hub coupling: the torques of its static start, then a
       straight-line torque ramp over one step. The impulse of a ramp r over H equals that of
       the torque held at its mid-step value, so the pinion speeds after the step agree to the
       change of the mesh torques over the step (far below the 0.05 rad/s checked). */
    HgmUnit *p = hgm_unit_create(HGM_UNIT_KIND_PAIR, NULL, NULL, HGM_FIDELITY_TABLE, 128, 0, 0);
    HgmUnit *q = hgm_unit_create(HGM_UNIT_KIND_PAIR, NULL, NULL, HGM_FIDELITY_TABLE, 128, 0, 0);
    CHECK(p != NULL && q != NULL, "pair units: %s", hgm_unit_last_error(NULL));
    CHECK(hgm_unit_set_hub_coupling(p, -1.0, 0.0, 0.0, 0.0) == HGM_STATUS_INVALID_ARGUMENT,
          "negative coupling");
    CHECK(strstr(hgm_unit_last_error(p), "c_p") != NULL, "message: %s", hgm_unit_last_error(p));
    CHECK(hgm_unit_set_hub_coupling(p, 984.0, 0.04, 984.0, 0.04) == HGM_STATUS_OK, "%s",
          hgm_unit_last_error(p));
    HgmUnitOutputs o0, op, oq;
    for (int i = 0; i < 2; i++) {
        HgmUnit *x = i ? q : p;
        CHECK(hgm_unit_start_static(x, 0.0, 300.0) == HGM_STATUS_OK, "%s", hgm_unit_last_error(x));
    }
    CHECK(hgm_unit_outputs(p, &o0) == HGM_STATUS_OK, "%s", hgm_unit_last_error(p));
    const double r = 2e4, H = 1e-4;
    HgmUnitInputs pin = {0}, qin = {0};
    pin.tau_p = o0.tau_p;
    pin.tau_g = o0.tau_g;
    qin = pin;
    qin.tau_p += 0.5 * r * H;
    HgmUnitInputRates rates = {0};
    rates.tau_p_rate = NAN;
    CHECK(hgm_unit_set_inputs(p, &pin) == HGM_STATUS_OK, "%s", hgm_unit_last_error(p));
    CHECK(hgm_unit_set_input_rates(p, &rates) == HGM_STATUS_INVALID_ARGUMENT, "NaN rate");
    CHECK(strstr(hgm_unit_last_error(p), "tau_p_rate") != NULL, "message: %s",
          hgm_unit_last_error(p));
    rates.tau_p_rate = r;
    CHECK(hgm_unit_set_input_rates(p, &rates) == HGM_STATUS_OK, "%s", hgm_unit_last_error(p));
    CHECK(hgm_unit_set_inputs(q, &qin) == HGM_STATUS_OK, "%s", hgm_unit_last_error(q));
    CHECK(hgm_unit_advance(p, H) == HGM_STATUS_OK, "%s", hgm_unit_last_error(p));
    CHECK(hgm_unit_advance(q, H) == HGM_STATUS_OK, "%s", hgm_unit_last_error(q));
    CHECK(hgm_unit_outputs(p, &op) == HGM_STATUS_OK && hgm_unit_outputs(q, &oq) == HGM_STATUS_OK,
          "outputs");
    CHECK(fabs(op.w_p - oq.w_p) < 0.05 && op.w_p > o0.w_p && isfinite(op.mesh.te),
          "ramp vs mid-step hold: w_p %.9g vs %.9g (start %.9g)", op.w_p, oq.w_p, o0.w_p);
    hgm_unit_free(p);
    hgm_unit_free(q);
}

/* ------------------------------------------------------------------ FMI functions */

static char last_message[1024];
static int messages = 0;

/* A printf-style logger, as an importer writes it. */
static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    (void)env;
    va_list ap;
    va_start(ap, message);
    vsnprintf(last_message, sizeof last_message, message, ap);
    va_end(ap);
    messages++;
    printf("  [%s %d %s] %s\n", instance, (int)status, category, last_message);
}

static void test_fmi2(const char *guid) {
    CHECK(strcmp(fmi2GetVersion(), "2.0") == 0, "version");
    CHECK(strcmp(fmi2GetTypesPlatform(), "default") == 0, "types platform");
    fmi2FreeInstance(NULL);

    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    fmi2Component c = fmi2Instantiate("c", fmi2CoSimulation, "{wrong}", NULL, &cb, fmi2False,
                                      fmi2False);
    CHECK(c == NULL, "wrong GUID");
    CHECK(strstr(last_message, "fmuGUID `{wrong}`") != NULL, "message: %s", last_message);
    c = fmi2Instantiate("c", (fmi2Type)7, guid, NULL, &cb, fmi2False, fmi2False);
    CHECK(c == NULL, "fmuType 7");

    /* A resource URI with a bad escape: a warning whose text contains '%' (escaped for the
     * printf-style logger, so it arrives intact). */
    c = fmi2Instantiate("c", fmi2CoSimulation, guid, "file:///tmp/a%zz", &cb, fmi2False,
                        fmi2True);
    CHECK(c != NULL, "instance");
    if (c == NULL) return;
    CHECK(strstr(last_message, "bad escape `%zz`") != NULL, "message: %s", last_message);

    /* An illegal call sequence: a step before initialisation. */
    CHECK(fmi2DoStep(c, 0.0, 1e-3, fmi2True) == fmi2Error, "step before initialisation");
    CHECK(strstr(last_message, "fmi2DoStep: not allowed in state instantiated") != NULL,
          "message: %s", last_message);
    CHECK(fmi2Reset(c) == fmi2OK, "reset from the error state");
    fmi2ValueReference vr = 0; /* phi_p */
    fmi2Real nan = NAN;
    CHECK(fmi2SetReal(c, &vr, 1, &nan) == fmi2Error, "NaN input");
    CHECK(strstr(last_message, "input `phi_p` = NaN is not finite") != NULL, "message: %s",
          last_message);
    fmi2FreeInstance(c);
}

/* ------------------------------------------------------------------ Model Exchange */

/* Event iteration and continuous-time mode after initialisation. */
static void to_continuous_time(fmi2Component c) {
    fmi2EventInfo info;
    memset(&info, 0xff, sizeof info);
    CHECK(fmi2NewDiscreteStates(c, &info) == fmi2OK, "new discrete states");
    CHECK(info.newDiscreteStatesNeeded == fmi2False && info.terminateSimulation == fmi2False &&
              info.nextEventTimeDefined == fmi2False,
          "event info");
    CHECK(fmi2EnterContinuousTimeMode(c) == fmi2OK, "continuous-time mode");
}

/* The mesh element in Model Exchange (no states, direct feedthrough) and its directional
 * derivative dM_F_p/dphi_p against a central difference of the output. */
static void test_me_mesh(const char *guid) {
    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    fmi2Component c = fmi2Instantiate("me", fmi2ModelExchange, guid, NULL, &cb, fmi2False,
                                      fmi2False);
    CHECK(c != NULL, "ME instance of the mesh");
    if (c == NULL) return;
    fmi2ValueReference slices = HelicalGearMesh_vr_slices;
    fmi2Integer n_slices = 30;
    CHECK(fmi2SetInteger(c, &slices, 1, &n_slices) == fmi2OK, "slices");
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK, "setup");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "init");
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "exit init");
    to_continuous_time(c);
    CHECK(fmi2SetTime(c, 0.25) == fmi2OK, "set time");
    CHECK(fmi2GetDerivatives(c, NULL, 0) == fmi2OK, "no states: nx = 0");
    CHECK(fmi2GetEventIndicators(c, NULL, 0) == fmi2OK, "no event indicators");
    const fmi2ValueReference in[4] = {HelicalGearMesh_vr_phi_p, HelicalGearMesh_vr_phi_g,
                                      HelicalGearMesh_vr_w_p, HelicalGearMesh_vr_w_g};
    double phi_p = 0.013, te = 15e-6;
    double x[4] = {phi_p, phi_g_for(phi_p, te), 300.0, -300.0 * G_P / G_G};
    CHECK(fmi2SetReal(c, in, 4, x) == fmi2OK, "inputs");
    fmi2ValueReference mf = HelicalGearMesh_vr_M_F_p;
    double seed = 1.0, exact = 0.0;
    CHECK(fmi2GetDirectionalDerivative(c, &mf, 1, &in[0], 1, &seed, &exact) == fmi2OK,
          "directional derivative: %s", last_message);
    double d = 2e-9, mp = 0.0, mm = 0.0;
    x[0] = phi_p + d;
    CHECK(fmi2SetReal(c, in, 4, x) == fmi2OK && fmi2GetReal(c, &mf, 1, &mp) == fmi2OK, "+");
    x[0] = phi_p - d;
    CHECK(fmi2SetReal(c, in, 4, x) == fmi2OK && fmi2GetReal(c, &mf, 1, &mm) == fmi2OK, "-");
    double central = (mp - mm) / (2 * d);
    CHECK(exact > 0.0 && fabs(exact - central) < 1e-5 * fabs(exact),
          "dM_F_p/dphi_p exact %.10g, central %.10g", exact, central);
    CHECK(fmi2DoStep(c, 0.0, 1e-3, fmi2True) == fmi2Error, "no doStep in Model Exchange");
    fmi2FreeInstance(c);
}

/* The whole drive in Model Exchange: states, nominals, derivatives, a few steps of the
 * master's own explicit midpoint rule near the static equilibrium, and a directional
 * derivative of the state derivative against a central difference. */
static void test_me_drive(void) {
    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    fmi2Component c = fmi2Instantiate("me_drive", fmi2ModelExchange, HelicalGearDrive_GUID,
                                      NULL, &cb, fmi2False, fmi2False);
    CHECK(c != NULL, "ME instance of the drive");
    if (c == NULL) return;
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK, "setup");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "init");
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "exit init: %s", last_message);
    to_continuous_time(c);
    enum { NX = 8, TE_I = 2, WP_I = 4 };
    double x[NX], dx[NX], nom[NX], xm[NX], dxm[NX];
    CHECK(fmi2GetContinuousStates(c, x, NX) == fmi2OK, "states");
    CHECK(fmi2GetContinuousStates(c, x, NX - 1) == fmi2Error, "wrong nx");
    CHECK(strstr(last_message, "8 continuous states") != NULL, "message: %s", last_message);
    CHECK(fmi2Reset(c) == fmi2OK, "reset");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK && fmi2ExitInitializationMode(c) == fmi2OK,
          "init again");
    to_continuous_time(c);
    CHECK(fmi2GetNominalsOfContinuousStates(c, nom, NX) == fmi2OK, "nominals");
    CHECK(fmi2GetContinuousStates(c, x, NX) == fmi2OK, "states");
    double te0 = x[TE_I];
    CHECK(te0 > 0.0 && te0 < 1e-4 && fabs(x[WP_I] - 300.0) < 1e-9 && nom[TE_I] < 1e-4,
          "start: TE %g, w_p %g, TE nominal %g", te0, x[WP_I], nom[TE_I]);
    double t = 0.0, h = 1e-6;
    for (int k = 0; k < 50; k++) {
        CHECK(fmi2SetTime(c, t) == fmi2OK && fmi2SetContinuousStates(c, x, NX) == fmi2OK &&
                  fmi2GetDerivatives(c, dx, NX) == fmi2OK,
              "derivatives at t = %g: %s", t, last_message);
        for (int i = 0; i < NX; i++) xm[i] = x[i] + 0.5 * h * dx[i];
        CHECK(fmi2SetTime(c, t + 0.5 * h) == fmi2OK && fmi2SetContinuousStates(c, xm, NX) == fmi2OK &&
                  fmi2GetDerivatives(c, dxm, NX) == fmi2OK,
              "midpoint");
        for (int i = 0; i < NX; i++) x[i] += h * dxm[i];
        t += h;
        fmi2Boolean enter = fmi2True, stop = fmi2True;
        CHECK(fmi2CompletedIntegratorStep(c, fmi2True, &enter, &stop) == fmi2OK && !enter && !stop,
              "completed integrator step");
    }
    CHECK(fmi2SetContinuousStates(c, x, NX) == fmi2OK, "set");
    fmi2ValueReference te_vr = HelicalGearDrive_vr_TE;
    double te = 0.0;
    CHECK(fmi2GetReal(c, &te_vr, 1, &te) == fmi2OK && fabs(te - te0) < 0.5 * te0,
          "TE after 50 us: %g (start %g)", te, te0);
    /* d der(v_TE) / d TE: the mesh stiffness seen by the TE coordinate. */
    fmi2ValueReference unk = HelicalGearDrive_vr_der_v_TE, known = HelicalGearDrive_vr_TE;
    double seed = 1.0, exact = 0.0, plus[NX], minus[NX];
    CHECK(fmi2GetDirectionalDerivative(c, &unk, 1, &known, 1, &seed, &exact) == fmi2OK,
          "directional derivative: %s", last_message);
    double d = 1e-5 * nom[TE_I];
    x[TE_I] += d;
    CHECK(fmi2SetContinuousStates(c, x, NX) == fmi2OK && fmi2GetDerivatives(c, plus, NX) == fmi2OK, "+");
    x[TE_I] -= 2 * d;
    CHECK(fmi2SetContinuousStates(c, x, NX) == fmi2OK && fmi2GetDerivatives(c, minus, NX) == fmi2OK, "-");
    double central = (plus[6] - minus[6]) / (2 * d);
    CHECK(exact < 0.0 && fabs(exact - central) < 1e-5 * fabs(exact),
          "d der(v_TE)/dTE exact %.10g, central %.10g", exact, central);
    double nan = NAN;
    x[0] = nan;
    CHECK(fmi2SetContinuousStates(c, x, NX) == fmi2Error, "NaN state");
    CHECK(strstr(last_message, "(`phi_p`) = NaN") != NULL, "message: %s", last_message);
    fmi2FreeInstance(c);
}

/* ------------------------------------------------------------------ extreme inputs */

/* TE = a*b + c*d rounded once (two-product with fma): the reference for huge angles. */
static double dot2(double a, double b, double c, double d) {
    double p1 = a * b, e1 = fma(a, b, -p1);
    double p2 = c * d, e2 = fma(c, d, -p2);
    double s = p1 + p2, bb = s - p1, es = (p1 - (s - bb)) + (p2 - bb);
    return s + (es + (e1 + e2));
}

static void test_extremes(const char *guid, int repeat) {
    const char *names[4] = {"phi_p", "phi_g", "w_p", "w_g"};
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    HgmOutputs out;
    char want[64];

    HgmModel *m = hgm_create_default();
    CHECK(m != NULL, "default model: %s", hgm_last_error(NULL));
    if (m == NULL) return;
    for (int i = 0; i < 4; i++) {
        for (int k = 0; k < 3; k++) {
            double v[4] = {0.01, -0.0060851, 100.0, -63.83};
            v[i] = bad[k];
            CHECK(hgm_evaluate(m, v[0], v[1], v[2], v[3], &out) == HGM_STATUS_INVALID_ARGUMENT,
                  "%s = %g", names[i], bad[k]);
            snprintf(want, sizeof want, "`%s` = ", names[i]);
            CHECK(strstr(hgm_last_error(m), want) != NULL, "message: %s", hgm_last_error(m));
        }
    }
    /* 1e12 rad: TE is the correctly rounded phi_p*g_p + phi_g*g_g of the given doubles. */
    const double huge[3] = {1e12, -1e12, 7.77e11};
    for (int i = 0; i < 3; i++) {
        double phi_p = huge[i], phi_g = (20e-6 - phi_p * G_P) / G_G;
        CHECK(hgm_evaluate(m, phi_p, phi_g, 150.0, -95.7, &out) == HGM_STATUS_OK, "%s",
              hgm_last_error(m));
        double te = dot2(phi_p, G_P, phi_g, G_G);
        CHECK(out.te == te, "phi_p = %g: TE %.17g vs %.17g", phi_p, out.te, te);
        CHECK(isfinite(out.m_f_p) && (te <= 0.0 || out.m_f_p > 0.0), "M_F_p = %g", out.m_f_p);
    }
    /* Zero and negative speeds. */
    const double speeds[3][2] = {{0.0, 0.0}, {-100.0, 63.83}, {-1e4, 1e4}};
    for (int i = 0; i < 3; i++) {
        CHECK(hgm_evaluate(m, 0.01, -0.0060851, speeds[i][0], speeds[i][1], &out) ==
                  HGM_STATUS_OK, "%s", hgm_last_error(m));
        double dte = speeds[i][0] * G_P + speeds[i][1] * G_G;
        CHECK(isfinite(out.m_d_p) && out.m_d_p * dte >= 0.0, "M_D_p = %g, dTE/dt = %g",
              out.m_d_p, dte);
    }
    hgm_free(m);
    for (int i = 0; i < repeat; i++) {
        HgmModel *h = hgm_create_default();
        CHECK(h != NULL, "create #%d", i);
        hgm_free(h);
    }

    /* FMI: NaN/Inf in every input is an error that names it in the log. */
    fmi2CallbackFunctions cb = {logger, NULL, NULL, NULL, NULL};
    for (int i = 0; i < repeat; i++) {
        fmi2Component c = fmi2Instantiate("r", fmi2CoSimulation, guid, NULL, &cb, fmi2False,
                                          fmi2False);
        CHECK(c != NULL, "instantiate #%d", i);
        fmi2FreeInstance(c);
    }
    fmi2Component c =
        fmi2Instantiate("x", fmi2CoSimulation, guid, NULL, &cb, fmi2False, fmi2False);
    CHECK(c != NULL, "instance");
    if (c == NULL) return;
    CHECK(fmi2Terminate(c) == fmi2Error, "terminate before initialisation");
    CHECK(strstr(last_message, "not allowed in state") != NULL, "message: %s", last_message);
    CHECK(fmi2Reset(c) == fmi2OK, "reset");
    CHECK(fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK, "setup");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter");
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "exit");
    fmi2ValueReference in_vr[4] = {0, 1, 2, 3};
    for (int i = 0; i < 4; i++) {
        for (int k = 0; k < 3; k++) {
            CHECK(fmi2SetReal(c, &in_vr[i], 1, &bad[k]) == fmi2Error, "%s = %g", names[i],
                  bad[k]);
            snprintf(want, sizeof want, "input `%s` = ", names[i]);
            CHECK(strstr(last_message, want) != NULL, "message: %s", last_message);
            CHECK(fmi2Reset(c) == fmi2OK, "reset");
            CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter");
            CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "exit");
        }
    }
    fmi2ValueReference unknown = 9999;
    fmi2Real x = 0;
    CHECK(fmi2GetReal(c, &unknown, 1, &x) == fmi2Error, "unknown value reference");
    CHECK(strstr(last_message, "9999") != NULL, "message: %s", last_message);
    CHECK(fmi2Reset(c) == fmi2OK, "reset");
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK, "enter");
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK, "exit");
    double v[4] = {1e12, (20e-6 - 1e12 * G_P) / G_G, -100.0, 63.83};
    CHECK(fmi2SetReal(c, in_vr, 4, v) == fmi2OK, "1e12 rad");
    fmi2ValueReference te_vr = 14;
    CHECK(fmi2GetReal(c, &te_vr, 1, &x) == fmi2OK && x == dot2(v[0], G_P, v[1], G_G),
          "TE at 1e12 rad through the FMU: %.17g", x);
    CHECK(fmi2Terminate(c) == fmi2OK, "terminate");
    CHECK(fmi2DoStep(c, 0.0, 1e-3, fmi2True) == fmi2Error, "step after terminate");
    fmi2FreeInstance(c);
}

int main(int argc, char **argv) {
    if (argc != 2 && argc != 3) {
        fprintf(stderr, "usage: %s GUID [REPEAT]\n", argv[0]);
        return 2;
    }
    int repeat = argc == 3 ? atoi(argv[2]) : 1000;
    test_fmi2(argv[1]);
    test_me_mesh(argv[1]);
    test_capi();
    /* The units (and the table-fidelity model of test_capi) build a mesh table (about 2 s
     * natively, minutes under valgrind): the valgrind run of tests/python/test_c_api.py sets
     * HGM_TEST_SKIP_UNITS=1. */
    const char *skip_units = getenv("HGM_TEST_SKIP_UNITS");
    if (!(skip_units && strcmp(skip_units, "1") == 0)) {
        test_units();
        test_me_drive();
    }
    test_extremes(argv[1], repeat);
    if (failures) {
        fprintf(stderr, "%d check(s) failed\n", failures);
        return 1;
    }
    printf("all C checks passed\n");
    return 0;
}
