//! fbd-contact (to be written).
