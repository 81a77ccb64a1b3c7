//! Times of steps written as the decimal of `k·Δt`.
//!
//! `k·Δt` computed in floating point is often not the double nearest to the
//! decimal the user means (`35 × 0.01 = 0.35000000000000003`). The files
//! therefore write the exact decimal product of `k` and the shortest
//! decimal of Δt (`0.35`), computed in integer arithmetic: it reads back as
//! the double nearest to `k·Δt`, and the same configuration gives the same
//! bytes. A time inside a step retried in sub-steps (`j·Δt/2^m`, m ≤ 6,
//! at most 64 sub-steps) is written the same way, as the exact decimal of
//! `j·Δt/2^m` (`0.35625` for the third sixteenth of a 0.3 s step); any
//! other time as the shortest decimal that reads back to its double.

use std::io::{self, Write};

/// The decimal digits of one Δt: `Δt = mantissa · 10^-scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepTimes {
    dt: f64,
    /// `None` when Δt's decimal does not fit the integer arithmetic (then
    /// every time is written by its shortest decimal).
    digits: Option<(u64, u32)>,
}

/// Longest decimal [`StepTimes::write`] produces.
const BUF: usize = 64;

/// Most halvings of Δt a sub-step time is recognised at (64 sub-steps, the
/// simulator's limit).
const MAX_HALVINGS: u32 = 6;

impl StepTimes {
    /// The times of a run with time step `dt` (s).
    pub fn new(dt: f64) -> Self {
        Self {
            dt,
            digits: decimal_digits(dt),
        }
    }

    /// Writes the time of step `k`, whose floating-point time is `t`, to
    /// `out`: the decimal `k·Δt` when `t` is that step's time, otherwise
    /// the shortest decimal of `t`. No allocation.
    pub fn write(&self, out: &mut impl Write, k: usize, t: f64) -> io::Result<()> {
        let mut buf = [0u8; BUF];
        match self.exact(k, t, &mut buf) {
            Some(n) => out.write_all(&buf[..n]),
            None => out.write_all(ryu::Buffer::new().format(t).as_bytes()),
        }
    }

    /// The time of step `k` (floating-point time `t`) as a string
    /// ([`StepTimes::write`]).
    pub fn string(&self, k: usize, t: f64) -> String {
        let mut v = Vec::with_capacity(24);
        // Writing to a Vec cannot fail.
        let _ = self.write(&mut v, k, t);
        String::from_utf8(v).unwrap_or_else(|_| t.to_string())
    }

    /// The double nearest to the decimal of step `k` (for JSON, whose
    /// writer prints the shortest decimal of a double): `0.35`, not
    /// `0.35000000000000003`. `t` itself when it is not a whole step.
    pub fn value(&self, k: usize, t: f64) -> f64 {
        let mut buf = [0u8; BUF];
        self.exact(k, t, &mut buf)
            .and_then(|n| std::str::from_utf8(&buf[..n]).ok()?.parse().ok())
            .unwrap_or(t)
    }

    /// Writes the decimal of `k·Δt` into `buf` and returns its length, or,
    /// when `t` is not the time of step `k`, that of the sub-step time
    /// `j·Δt/2^m` equal to `t` (m ≤ [`MAX_HALVINGS`]); `None` when `t` is
    /// neither or the digits overflow.
    fn exact(&self, k: usize, t: f64, buf: &mut [u8; BUF]) -> Option<usize> {
        if let Some(n) = self.exact_scaled(k as u128, 0, t, buf) {
            return Some(n);
        }
        (1..=MAX_HALVINGS).find_map(|m| {
            let j = (t / self.dt * f64::from(1u32 << m)).round();
            (0.0..1e18)
                .contains(&j)
                .then(|| self.exact_scaled(j as u128, m, t, buf))
                .flatten()
        })
    }

    /// The decimal of `j·Δt/2^m` (`= j·mantissa·5^m · 10^-(scale+m)`) into
    /// `buf`, when it reads back within round-off of `t`.
    fn exact_scaled(&self, j: u128, m: u32, t: f64, buf: &mut [u8; BUF]) -> Option<usize> {
        let (mantissa, scale) = self.digits?;
        let scale = scale + m;
        let product = u128::from(mantissa)
            .checked_mul(5u128.checked_pow(m)?)?
            .checked_mul(j)?;
        let mut digits = [0u8; 40];
        let mut len = 0;
        let mut v = product;
        loop {
            digits[len] = b'0' + (v % 10) as u8;
            len += 1;
            v /= 10;
            if v == 0 {
                break;
            }
        }
        digits[..len].reverse();
        let scale = scale as usize;
        // Integer part and fraction, padding with leading zeros.
        let mut n = 0;
        if len <= scale {
            push(buf, &mut n, b'0')?;
        } else {
            for &d in &digits[..len - scale] {
                push(buf, &mut n, d)?;
            }
        }
        push(buf, &mut n, b'.')?;
        let frac_start = n;
        for _ in len..scale {
            push(buf, &mut n, b'0')?;
        }
        for &d in &digits[len.saturating_sub(scale)..len] {
            push(buf, &mut n, d)?;
        }
        while n > frac_start + 1 && buf[n - 1] == b'0' {
            n -= 1;
        }
        if n == frac_start {
            push(buf, &mut n, b'0')?;
        }
        // Only a whole step is written as k·Δt.
        let value: f64 = std::str::from_utf8(&buf[..n]).ok()?.parse().ok()?;
        let tol = 1e-9 * self.dt.abs().max(f64::MIN_POSITIVE);
        ((value - t).abs() <= tol).then_some(n)
    }
}

/// Appends `b` at `buf[*n]`; `None` when full.
fn push(buf: &mut [u8; BUF], n: &mut usize, b: u8) -> Option<()> {
    *buf.get_mut(*n)? = b;
    *n += 1;
    Some(())
}

/// `(mantissa, scale)` with `x = mantissa · 10^-scale`, from the shortest
/// decimal of `x` (finite, ≥ 0).
fn decimal_digits(x: f64) -> Option<(u64, u32)> {
    if !(x.is_finite() && x >= 0.0) {
        return None;
    }
    let mut b = ryu::Buffer::new();
    let s = b.format_finite(x);
    let (sig, exp) = match s.split_once('e') {
        Some((sig, exp)) => (sig, exp.parse::<i32>().ok()?),
        None => (s, 0),
    };
    let (int, frac) = sig.split_once('.').unwrap_or((sig, ""));
    let frac = frac.trim_end_matches('0');
    let mut mantissa: u64 = format!("{int}{frac}").parse().ok()?;
    let mut scale = frac.len() as i32 - exp;
    while scale < 0 {
        mantissa = mantissa.checked_mul(10)?;
        scale += 1;
    }
    (scale <= 30).then_some((mantissa, scale as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_steps_are_the_decimal_of_k_dt() {
        let s = StepTimes::new(0.01);
        assert_eq!(35.0 * 0.01, 0.35000000000000003);
        assert_eq!(s.string(35, 35.0 * 0.01), "0.35");
        assert_eq!(s.string(0, 0.0), "0.0");
        assert_eq!(s.string(100, 100.0 * 0.01), "1.0");
        assert_eq!(s.string(123, 123.0 * 0.01), "1.23");
        assert_eq!(s.value(35, 35.0 * 0.01), 0.35);
        let s = StepTimes::new(1e-4);
        assert_eq!(s.string(2114, 2114.0 * 1e-4), "0.2114");
        assert_eq!(s.string(7, 7.0 * 1e-4), "0.0007");
        let s = StepTimes::new(2.5e-7);
        assert_eq!(s.string(3, 3.0 * 2.5e-7), "0.00000075");
        let s = StepTimes::new(0.5);
        assert_eq!(s.string(3, 1.5), "1.5");
        let s = StepTimes::new(20.0);
        assert_eq!(s.string(3, 60.0), "60.0");
    }

    #[test]
    fn every_decimal_reads_back_to_the_nearest_double() {
        for dt in [0.01, 0.001, 0.0001, 0.002, 0.003, 0.007, 1.0 / 3.0] {
            let s = StepTimes::new(dt);
            for k in 0..5000 {
                let t = k as f64 * dt;
                let text = s.string(k, t);
                let back: f64 = text.parse().unwrap();
                assert!((back - t).abs() <= 1e-12 * t.max(1.0), "{dt} {k}: {text}");
            }
        }
    }

    #[test]
    fn a_sub_step_time_keeps_its_own_decimal() {
        let s = StepTimes::new(0.01);
        assert_eq!(s.string(35, 0.355), "0.355");
        assert_eq!(s.value(35, 0.355), 0.355);
        // A 0.3 s step retried in 16 sub-steps: its third sub-step starts at
        // 0.3 + 3·0.01875, which floating point sums to 0.35624999999999996.
        let s = StepTimes::new(0.3);
        let t = 0.3 + 3.0 * (0.3 / 16.0);
        assert_eq!(t, 0.35624999999999996);
        assert_eq!(s.string(1, t), "0.35625");
        assert_eq!(s.string(1, 0.3 + 0.3 / 64.0), "0.3046875");
        // Not a sub-step time: its own shortest decimal.
        assert_eq!(s.string(1, 0.31), "0.31");
    }
}
