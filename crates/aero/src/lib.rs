//! Quasi-steady blade-element aerodynamics and wing planform integrals (thesis §3.2.4).
