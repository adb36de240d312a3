//! Local contact deformation (Weber–Banaschek, Eqs. 10–11) and Hertz pressure (Eq. 15).
