//! Numbers exactly as written.
//!
//! The control gives meaning to the form of a number, not only to its value:
//! `X100` and `X100.` are both 100 mm, but `R1=864` stores 0.864 while
//! `R1=864.` stores 864, `F1.2` is m/min while `F1200` is mm/min, and digit
//! limits count the digits that were written. So a number keeps its sign,
//! its digits on both sides of the point, and whether a point was written.

use std::fmt;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sign {
    Plus,
    Minus,
}

/// A decimal number in its written form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Decimal {
    sign: Option<Sign>,
    has_point: bool,
    int_digits: u16,
    leading_zeros: u16,
    frac_digits: u16,
    /// All digits as one integer (`12.50` → 1250); `None` past 19 digits,
    /// far beyond any address's format.
    mantissa: Option<u64>,
}

impl Decimal {
    /// Reads `digits` (`[0-9]*(.[0-9]*)?`) with an optional written sign.
    /// Returns `None` when there is no digit at all (`.` alone) or the text
    /// has other characters.
    pub fn parse(sign: Option<Sign>, digits: &str) -> Option<Decimal> {
        // One pass: programs hold millions of numbers.
        let mut mantissa = Some(0u64);
        let mut point = None;
        let mut leading_zeros = 0;
        for (i, byte) in digits.bytes().enumerate() {
            match byte {
                b'0'..=b'9' => {
                    if byte == b'0' && point.is_none() && leading_zeros == i {
                        leading_zeros += 1;
                    }
                    mantissa = mantissa.and_then(|m| m.checked_mul(10)?.checked_add(u64::from(byte - b'0')));
                }
                b'.' if point.is_none() => point = Some(i),
                _ => return None,
            }
        }
        let int_len = point.unwrap_or(digits.len());
        let frac_len = point.map_or(0, |point| digits.len() - point - 1);
        if int_len + frac_len == 0 {
            return None;
        }
        let count = |n: usize| u16::try_from(n).unwrap_or(u16::MAX);
        Some(Decimal {
            sign,
            has_point: point.is_some(),
            int_digits: count(int_len),
            leading_zeros: count(leading_zeros),
            frac_digits: count(frac_len),
            mantissa,
        })
    }

    /// The sign as written; `None` when no sign was written.
    pub fn sign(&self) -> Option<Sign> {
        self.sign
    }

    pub fn is_negative(&self) -> bool {
        self.sign == Some(Sign::Minus) && self.mantissa != Some(0)
    }

    pub fn has_point(&self) -> bool {
        self.has_point
    }

    /// Digits written before the point, leading zeros included.
    pub fn int_digits(&self) -> u32 {
        u32::from(self.int_digits)
    }

    /// Digits written before the point without leading zeros (`0.5` → 0,
    /// `002500` → 4).
    pub fn significant_int_digits(&self) -> u32 {
        u32::from(self.int_digits - self.leading_zeros)
    }

    /// Digits written after the point.
    pub fn frac_digits(&self) -> u32 {
        u32::from(self.frac_digits)
    }

    /// Digits after the point without trailing zeros (`1.2500` → 2).
    pub fn significant_frac_digits(&self) -> u32 {
        let mut mantissa = self.mantissa.unwrap_or(1);
        let mut digits = self.frac_digits();
        while digits > 0 && mantissa.is_multiple_of(10) {
            mantissa /= 10;
            digits -= 1;
        }
        digits
    }

    /// The value scaled by `10^scale` as an exact integer (`1.25` at scale 3
    /// is 1250). `None` if more than `scale` decimals were written with a
    /// non-zero digit among the extra ones, or on overflow.
    pub fn scaled(&self, scale: u32) -> Option<i128> {
        let mantissa = i128::from(self.mantissa?);
        let frac_digits = self.frac_digits();
        let magnitude = if scale == frac_digits {
            mantissa
        } else if scale > frac_digits {
            mantissa.checked_mul(10i128.checked_pow(scale - frac_digits)?)?
        } else {
            let divisor = 10i128.checked_pow(frac_digits - scale)?;
            if mantissa % divisor != 0 {
                return None;
            }
            mantissa / divisor
        };
        Some(if self.sign == Some(Sign::Minus) { -magnitude } else { magnitude })
    }

    /// The value as written (decimal point respected, no unit applied).
    pub fn to_f64(&self) -> f64 {
        let magnitude = match self.mantissa {
            Some(m) => {
                const POWERS: [f64; 10] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];
                let divisor = POWERS.get(usize::from(self.frac_digits)).copied();
                m as f64 / divisor.unwrap_or_else(|| 10f64.powi(i32::from(self.frac_digits)))
            }
            None => f64::INFINITY,
        };
        if self.sign == Some(Sign::Minus) { -magnitude } else { magnitude }
    }
}

impl fmt::Display for Decimal {
    /// Writes the number back in its written form (`-002.50` stays `-002.50`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.sign {
            Some(Sign::Plus) => f.write_str("+")?,
            Some(Sign::Minus) => f.write_str("-")?,
            None => {}
        }
        let width = usize::from(self.int_digits) + usize::from(self.frac_digits);
        let digits = match self.mantissa {
            Some(m) => format!("{m:0width$}"),
            None => "9".repeat(width),
        };
        let (int, frac) = digits.split_at(usize::from(self.int_digits));
        f.write_str(int)?;
        if self.has_point {
            write!(f, ".{frac}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dec(text: &str) -> Decimal {
        let (sign, digits) = match text.as_bytes()[0] {
            b'-' => (Some(Sign::Minus), &text[1..]),
            b'+' => (Some(Sign::Plus), &text[1..]),
            _ => (None, text),
        };
        Decimal::parse(sign, digits).unwrap()
    }

    #[test]
    fn keeps_the_written_form() {
        for text in ["0", "384.", ".12", "-0.864", "002500", "+10.000", "99999999", "-.5"] {
            assert_eq!(dec(text).to_string(), text);
        }
        assert!(Decimal::parse(None, ".").is_none());
        assert!(Decimal::parse(None, "").is_none());
    }

    proptest::proptest! {
        #[test]
        fn numbers_read_back_as_written(text in "[0-9]{0,9}(\\.[0-9]{0,9})?") {
            let parsed = Decimal::parse(None, &text);
            let has_digit = text.bytes().any(|b| b.is_ascii_digit());
            proptest::prop_assert_eq!(parsed.is_some(), has_digit);
            if let Some(decimal) = parsed {
                proptest::prop_assert_eq!(decimal.to_string(), text.clone());
                let zeros = text.bytes().take_while(|&b| b == b'0').count();
                proptest::prop_assert_eq!(decimal.significant_int_digits() as usize, text.split('.').next().unwrap().len() - zeros);
            }
        }
    }

    #[test]
    fn text_that_is_no_number_is_refused() {
        for text in ["", ".", "1.2.3", "1a", "-1", " 1"] {
            assert_eq!(Decimal::parse(None, text), None, "{text}");
        }
    }

    #[test]
    fn digit_counts() {
        let d = dec("002500");
        assert_eq!((d.int_digits(), d.significant_int_digits(), d.frac_digits()), (6, 4, 0));
        assert!(!d.has_point());
        let d = dec("0.250");
        assert_eq!((d.int_digits(), d.significant_int_digits(), d.frac_digits()), (1, 0, 3));
        assert!(d.has_point());
    }

    #[test]
    fn scaling_is_exact() {
        assert_eq!(dec("864").scaled(0), Some(864));
        assert_eq!(dec("-0.864").scaled(3), Some(-864));
        assert_eq!(dec("100.").scaled(3), Some(100_000));
        assert_eq!(dec("1.0005").scaled(3), None);
        assert_eq!(dec("1.2500").scaled(3), Some(1250));
        assert_eq!(dec("1.2500").significant_frac_digits(), 2);
        assert_eq!(dec("0.000").significant_frac_digits(), 0);
        assert_eq!(dec("1.5").to_f64(), 1.5);
        assert!(!dec("-0").is_negative());
    }
}
