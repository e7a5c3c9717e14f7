//! sweep: placeholder (filled by its issue).
