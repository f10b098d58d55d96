//! [`Bounds`]: a closed range of accepted values, declared once as a constant and read by
//! everything that needs it — the JSON Schema (`#[schemars(range(min = B.lo, max = B.hi))]`), the
//! reader's check ([`Bounds::contains`]) and its message ([`Bounds::text`]).

/// The closed range `lo … hi` of a quantity a file may set (units as its constant documents).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Least accepted value.
    pub lo: f64,
    /// Largest accepted value.
    pub hi: f64,
}

impl Bounds {
    /// The range `lo … hi` (`lo ≤ hi`, checked when the constant is evaluated).
    pub const fn new(lo: f64, hi: f64) -> Self {
        assert!(lo <= hi, "a range's lower end is above its upper end");
        Self { lo, hi }
    }

    /// Whether `x` is a finite number within the range (ends included).
    pub fn contains(self, x: f64) -> bool {
        x.is_finite() && self.lo <= x && x <= self.hi
    }

    /// The range as messages and documentation write it: `0.02 … 0.07`.
    pub fn text(self) -> String {
        format!("{} … {}", self.lo, self.hi)
    }
}

#[cfg(test)]
mod tests {
    use super::Bounds;

    #[test]
    fn a_range_holds_its_ends_and_nothing_beyond_or_not_finite() {
        let b = Bounds::new(0.02, 0.07);
        assert!(b.contains(0.02) && b.contains(0.07) && b.contains(0.05));
        assert!(!b.contains(0.019_999) && !b.contains(0.070_001));
        assert!(!b.contains(f64::NAN) && !b.contains(f64::INFINITY));
        assert_eq!(b.text(), "0.02 … 0.07");
    }
}
