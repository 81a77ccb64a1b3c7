//! Numbers quoted in messages: short at any magnitude.
//!
//! Rust's `{}` and `{:.3}` write every digit of a float in positional
//! notation, so a mistyped `1e300` in a configuration came back as a
//! 301-digit number inside a one-line error, and a time scale of
//! `1e-150` s as `0.000`. [`Num`] and [`Fixed`] write what `{}` and
//! `{:.p}` write for ordinary magnitudes — the messages of every
//! sensible input are unchanged — and switch to the exponent form
//! outside them. Every crate of the workspace quotes a user's values
//! through them; [`Quote`] is the `got …` of a configuration error.

use std::fmt;

/// Below this magnitude (non-zero) a number is written with an exponent.
const SMALL: f64 = 1e-5;
/// From this magnitude on a number is written with an exponent.
const LARGE: f64 = 1e15;

/// `x` as `{}` writes it (the shortest form that reads back the same)
/// for `1e-5 ≤ |x| < 1e15`, zero and non-finite values; otherwise as
/// `{:e}` (`1e300`, `-2.5e-9`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() || (SMALL..LARGE).contains(&a) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// `x` with `p` digits after the point, as `{:.p}` writes it, for
/// `|x| < 1e15` unless that would show a non-zero `x` as zero; otherwise
/// `p` digits after the point of the exponent form (`{:.pe}`: `1.000e300`,
/// `2.500e-9`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fixed(pub f64, pub usize);

impl fmt::Display for Fixed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Fixed(x, p) = *self;
        let a = x.abs();
        // The smallest magnitude that `{:.p}` shows with a non-zero digit.
        let shown = 0.5 * 10f64.powi(-i32::try_from(p).unwrap_or(i32::MAX));
        if x == 0.0 || !x.is_finite() || (a < LARGE && a >= shown) {
            write!(f, "{x:.p$}")
        } else {
            write!(f, "{x:.p$e}")
        }
    }
}

/// A value quoted in an error message: numbers short at any magnitude
/// ([`Num`]: `1e300`, not its 301 digits), text as it is.
pub trait Quote {
    /// The value as the message shows it.
    fn quote(&self) -> String;
}

impl Quote for f64 {
    fn quote(&self) -> String {
        Num(*self).to_string()
    }
}

impl Quote for str {
    fn quote(&self) -> String {
        self.to_owned()
    }
}

impl Quote for String {
    fn quote(&self) -> String {
        self.clone()
    }
}

impl Quote for usize {
    fn quote(&self) -> String {
        self.to_string()
    }
}

impl<T: Quote + ?Sized> Quote for &T {
    fn quote(&self) -> String {
        (**self).quote()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinary_numbers_are_written_as_before() {
        for x in [
            0.0, -0.0, 1.0, -1.0, 0.5, 9.81, 0.001, 1e-5, 123_456.75, 1e14,
        ] {
            assert_eq!(Num(x).to_string(), x.to_string());
        }
        for (x, p) in [(250.0, 3), (-0.0006, 3), (0.1, 6), (1e14, 1)] {
            assert_eq!(Fixed(x, p).to_string(), format!("{x:.p$}"));
        }
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(Num(x).to_string(), x.to_string());
            assert_eq!(Fixed(x, 3).to_string(), format!("{x:.3}"));
        }
    }

    #[test]
    fn extreme_numbers_are_short() {
        assert_eq!(Num(1e300).to_string(), "1e300");
        assert_eq!(Num(-1e15).to_string(), "-1e15");
        assert_eq!(Num(1e-9).to_string(), "1e-9");
        assert_eq!(Num(-2.5e-150).to_string(), "-2.5e-150");
        assert_eq!(Fixed(1e300, 3).to_string(), "1.000e300");
        assert_eq!(Fixed(2.5e-9, 3).to_string(), "2.500e-9");
        assert_eq!(Fixed(-0.0004, 3).to_string(), "-4.000e-4");
        assert_eq!(Fixed(-0.0004, 2).to_string(), "-4.00e-4");
        // Every float reads back from `Num` exactly.
        for x in [
            1e300,
            3.3e-7,
            -1.234_567_890_123e20,
            f64::MIN_POSITIVE,
            5e-324,
        ] {
            assert_eq!(Num(x).to_string().parse::<f64>().unwrap(), x);
            assert!(Num(x).to_string().len() <= 24, "{}", Num(x));
            assert!(Fixed(x, 6).to_string().len() <= 16, "{}", Fixed(x, 6));
        }
    }
}
