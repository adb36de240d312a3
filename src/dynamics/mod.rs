//! The 4-DOF torsional model of Eqs. 1–4 and its integrators.
