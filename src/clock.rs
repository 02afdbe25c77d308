//! The pipeline's stopwatch: `std::time::Instant` where the platform has a clock, and a
//! stopwatch that always reads zero on `wasm32-unknown-unknown`, where `Instant::now()`
//! panics at run time (the browser's clock needs JavaScript bindings, which polis does
//! not pull in).
//!
//! Limitations: on `wasm32-unknown-unknown` every [`CityStats`](crate::CityStats) timing
//! is zero; the city itself is unaffected (timings never steer generation).
//! `.ci/run` greps library code so no other `Instant::now()` slips in.

use std::time::Duration;

/// A point in time to measure durations from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Instant {
    #[cfg(not(all(target_arch = "wasm32", target_os = "unknown")))]
    at: std::time::Instant,
}

impl Instant {
    /// Now.
    pub(crate) fn now() -> Self {
        Instant {
            #[cfg(not(all(target_arch = "wasm32", target_os = "unknown")))]
            at: std::time::Instant::now(),
        }
    }

    /// The time since `self` (zero without a clock).
    pub(crate) fn elapsed(&self) -> Duration {
        #[cfg(not(all(target_arch = "wasm32", target_os = "unknown")))]
        {
            self.at.elapsed()
        }
        #[cfg(all(target_arch = "wasm32", target_os = "unknown"))]
        {
            Duration::ZERO
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn elapsed_grows() {
        let t = super::Instant::now();
        std::thread::sleep(std::time::Duration::from_millis(2));
        assert!(t.elapsed() >= std::time::Duration::from_millis(2));
    }
}
