//! A number as a message shows it: bounded in length whatever its size. Rust writes an
//! `f64` in full decimal, so a landmark's `scale = 1e-300` made a skip reason 447
//! characters long, most of them zeros (issue 74); every number a message takes from a
//! person's data or parameters goes through [`Num`].

use std::fmt;

/// Numbers from this size up, or under [`SMALL`], are shown with an exponent.
const LARGE: f64 = 1e15;
const SMALL: f64 = 1e-4;
/// The most decimals a message asks for.
const MAX_PLACES: usize = 6;

/// An `f64` shown in at most about 25 characters: as Rust writes it when it is between
/// 0.0001 and 10^15 (or 0, or not finite), else as `1e-300`; a precision (`{:.1}`) is kept,
/// up to six places.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let plain = x == 0.0 || !x.is_finite() || (SMALL..LARGE).contains(&x.abs());
        match (f.precision().map(|p| p.min(MAX_PLACES)), plain) {
            (Some(p), true) => write!(f, "{x:.p$}"),
            (Some(p), false) => write!(f, "{x:.p$e}"),
            (None, true) => write!(f, "{x}"),
            (None, false) => write!(f, "{x:e}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_number_is_short_and_the_usual_ones_read_as_before() {
        assert_eq!(Num(2.5).to_string(), "2.5");
        assert_eq!(Num(1000.0).to_string(), "1000");
        assert_eq!(Num(0.0).to_string(), "0");
        assert_eq!(format!("{:.1}", Num(12.345)), "12.3");
        assert_eq!(Num(1e-300).to_string(), "1e-300");
        assert_eq!(Num(-1e300).to_string(), "-1e300");
        assert_eq!(format!("{:.0}", Num(1e300)), "1e300");
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
        for x in [
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            1e15 - 1.0,
            0.0001,
            123_456.789_012_345,
        ] {
            for s in [Num(x).to_string(), format!("{:.3}", Num(x))] {
                assert!(s.len() <= 25, "{s}");
            }
        }
    }
}
