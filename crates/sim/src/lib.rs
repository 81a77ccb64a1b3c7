//! fbd-sim (to be written).
