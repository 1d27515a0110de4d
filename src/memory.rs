//! The memory budget of a run: a cap on the bytes the process holds on its
//! heap, checked by estimate before a mode commits to a canvas and, when
//! the program installs a counting allocator, on every allocation.
//!
//! * [`set_budget`] sets the cap (the command line's `--max-memory`,
//!   default [`DEFAULT_BUDGET`]).
//! * A mode that is about to allocate something large asks [`fits`] (or
//!   [`check`], which words the refusal) with its estimate, and lowers its
//!   resolution or refuses with one line before allocating.
//! * A counting allocator (the `flourish` binary installs one) reports
//!   each allocation and release through [`reserve`] and [`release`]; an
//!   allocation that would cross the cap is refused there, and the program
//!   ends with one line instead of an allocation abort.
//!
//! Without a counting allocator (the library in another program) the
//! counters stay at zero and [`fits`] compares an estimate with the cap
//! alone.

use crate::error::{Error, Result};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Default cap on the heap of a run: 1 GiB.
pub const DEFAULT_BUDGET: u64 = 1 << 30;

/// A cap and the bytes held under it.
struct Meter {
    /// The cap in bytes.
    budget: AtomicUsize,
    /// Bytes held now.
    held: AtomicUsize,
    /// Most bytes held at once so far.
    peak: AtomicUsize,
}

impl Meter {
    const fn new() -> Meter {
        Meter {
            budget: AtomicUsize::new(usize::MAX),
            held: AtomicUsize::new(0),
            peak: AtomicUsize::new(0),
        }
    }

    fn reserve(&self, bytes: usize) -> bool {
        let cap = self.budget.load(Ordering::Relaxed);
        let mut now = self.held.load(Ordering::Relaxed);
        loop {
            let Some(next) = now.checked_add(bytes).filter(|&n| n <= cap) else {
                return false;
            };
            match self
                .held
                .compare_exchange_weak(now, next, Ordering::Relaxed, Ordering::Relaxed)
            {
                Ok(_) => {
                    self.peak.fetch_max(next, Ordering::Relaxed);
                    return true;
                }
                Err(seen) => now = seen,
            }
        }
    }

    fn release(&self, bytes: usize) {
        self.held.fetch_sub(bytes, Ordering::Relaxed);
    }

    fn check(&self, what: &str, bytes: u64) -> Result<()> {
        if self.fits(bytes) {
            return Ok(());
        }
        let room = (self.budget.load(Ordering::Relaxed) as u64)
            .saturating_sub(self.held.load(Ordering::Relaxed) as u64);
        Err(Error::invalid(format!(
            "{what} needs about {}, more than the {} left of the memory budget (--max-memory)",
            in_words(bytes),
            in_words(room)
        )))
    }

    fn fits(&self, bytes: u64) -> bool {
        (self.held.load(Ordering::Relaxed) as u64).saturating_add(bytes)
            <= self.budget.load(Ordering::Relaxed) as u64
    }
}

/// The run's meter: no cap until [`set_budget`].
static METER: Meter = Meter::new();

/// Sets the cap on the bytes the run may hold at once.
pub fn set_budget(bytes: u64) {
    METER.budget.store(
        usize::try_from(bytes).unwrap_or(usize::MAX),
        Ordering::Relaxed,
    );
}

/// The cap in bytes (`usize::MAX` when none was set).
pub fn budget() -> u64 {
    METER.budget.load(Ordering::Relaxed) as u64
}

/// Bytes held now, as counted by the program's allocator (0 without one).
pub fn held() -> u64 {
    METER.held.load(Ordering::Relaxed) as u64
}

/// Most bytes held at once so far (0 without a counting allocator).
pub fn peak() -> u64 {
    METER.peak.load(Ordering::Relaxed) as u64
}

/// Counts `bytes` about to be allocated; false (and nothing counted) when
/// they would take the heap past the cap. For a counting allocator: it
/// does not allocate.
pub fn reserve(bytes: usize) -> bool {
    METER.reserve(bytes)
}

/// Counts `bytes` released. For a counting allocator: it does not allocate.
pub fn release(bytes: usize) {
    METER.release(bytes)
}

/// Whether `bytes` more would fit in the budget beside what is held now.
pub fn fits(bytes: u64) -> bool {
    METER.fits(bytes)
}

/// [`fits`], or an error naming `what` needs the memory, e.g. "a 9000×9000
/// px canvas needs about 2.4 GB, over the memory budget of 1.0 GB".
pub fn check(what: &str, bytes: u64) -> Result<()> {
    METER.check(what, bytes)
}

/// A byte count in MB or GB with one decimal, for messages.
pub fn in_words(bytes: u64) -> String {
    Size(bytes).to_string()
}

/// A byte count shown in MB, or in GB with one decimal from 1 GB up;
/// formatting it allocates nothing (the counting allocator's message
/// uses it).
#[derive(Clone, Copy, Debug)]
pub struct Size(pub u64);

impl std::fmt::Display for Size {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mb = self.0 as f64 / (1u64 << 20) as f64;
        if mb >= 1024.0 {
            write!(f, "{:.1} GB", mb / 1024.0)
        } else {
            write!(f, "{mb:.0} MB")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reserve_stops_at_the_cap_and_release_gives_back() {
        let m = Meter::new();
        m.budget.store(1000, Ordering::Relaxed);
        assert!(m.reserve(600));
        assert!(!m.reserve(500), "600 + 500 crosses 1000");
        assert_eq!(m.held.load(Ordering::Relaxed), 600);
        assert!(m.fits(400) && !m.fits(401));
        m.release(600);
        assert!(m.reserve(1000));
        assert_eq!(m.peak.load(Ordering::Relaxed), 1000);
        m.release(1000);
        assert_eq!(m.held.load(Ordering::Relaxed), 0);
    }

    #[test]
    fn a_refusal_names_what_needs_the_memory() {
        let m = Meter::new();
        m.budget.store(1 << 30, Ordering::Relaxed);
        assert!(m.reserve(1 << 29));
        assert!(m.check("a canvas", 1 << 29).is_ok());
        assert_eq!(
            m.check("a 9000×9000 px canvas", 3 << 29)
                .unwrap_err()
                .to_string(),
            "a 9000×9000 px canvas needs about 1.5 GB, \
             more than the 512 MB left of the memory budget (--max-memory)"
        );
    }

    #[test]
    fn sizes_read_in_megabytes_or_gigabytes() {
        assert_eq!(in_words(300 << 20), "300 MB");
        assert_eq!(in_words(3 << 29), "1.5 GB");
    }
}
