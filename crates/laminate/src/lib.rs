//! Laminate plate theory for piezoelectric bimorph actuators, flexures and PC-MEMS layups.
