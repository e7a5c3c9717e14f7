//! floquet: placeholder (filled by its issue).
