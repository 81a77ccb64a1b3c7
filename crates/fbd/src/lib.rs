//! fbd-dynamics (to be written).
