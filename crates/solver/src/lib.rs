//! fbd-solver (to be written).
