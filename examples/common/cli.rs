//! Flag values the examples' command lines share (each example parses its flags with
//! clap's derive API and includes this file with `#[path]`).

use polis::CityConfig;

/// The preset names, so clap lists them in `--help` and suggests the nearest.
pub fn preset_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(CityConfig::preset_names())
}

/// A finite, positive number of metres.
pub fn metres(text: &str) -> Result<f64, String> {
    let v: f64 = text.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{text} is not a positive number of metres"))
    }
}

/// An inclusive range of seeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Seeds {
    /// The first seed.
    pub first: u64,
    /// The last seed (at least `first`).
    pub last: u64,
}

impl Seeds {
    /// Every seed of the range, in order.
    pub fn iter(self) -> std::ops::RangeInclusive<u64> {
        self.first..=self.last
    }
}

/// `N` (one seed) or `FIRST-LAST` (inclusive, `FIRST ≤ LAST`).
pub fn seeds(text: &str) -> Result<Seeds, String> {
    let (a, b) = text.split_once('-').unwrap_or((text, text));
    let parse = |s: &str| {
        s.trim()
            .parse::<u64>()
            .map_err(|e| format!("{s:?}: {e}; give N or FIRST-LAST"))
    };
    let (first, last) = (parse(a)?, parse(b)?);
    if first > last {
        return Err(format!(
            "{first} is after {last}; give FIRST-LAST with FIRST ≤ LAST"
        ));
    }
    Ok(Seeds { first, last })
}
