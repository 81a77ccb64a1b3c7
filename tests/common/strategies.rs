//! Bounded, physical proptest strategies: the one place tests draw random
//! configurations from.
