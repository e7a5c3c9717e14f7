//! Euler-Lagrange wing dynamics, piezo actuator and time integration (thesis §3.2.3, Appendix A).
