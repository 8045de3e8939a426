//! A command table read while the run goes: a window of samples in a ring
//! that the host fills ahead of the integration and empties behind it, so a
//! record of any length runs in the memory of the window.
//!
//! The values are those of [`Signal::Table`](super::Signal::Table) on the
//! whole record (first-order hold between samples, held outside the
//! record), as long as the integration asks for times inside the window.
//! A time before the window (samples dropped too early) or after it while
//! the record goes on (samples not yet pushed) is an underrun: the value is
//! the nearest sample's and [`StreamedTable::underrun`] says so, for the host
//! to fail the run. Clones share the window: the host keeps one, the
//! circuit's signal reads another; the host changes it only between solver
//! steps, from the thread that runs the solve.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering::Relaxed};
use std::sync::Arc;

#[derive(Debug)]
struct Ring {
    time: Box<[AtomicU64]>,
    value: Box<[AtomicU64]>,
    mask: usize,
    /// Global index of the first sample held.
    lo: AtomicUsize,
    /// One past the global index of the last sample held.
    hi: AtomicUsize,
    /// The record's last sample has been pushed.
    done: AtomicBool,
    underrun: AtomicBool,
    /// The record's smallest and largest value (set by the host).
    range: [AtomicU64; 2],
}

/// A shared window on a long command table (see the module doc).
#[derive(Clone, Debug)]
pub struct StreamedTable(Arc<Ring>);

/// Two handles are equal when they share the window.
impl PartialEq for StreamedTable {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl StreamedTable {
    /// An empty window holding up to `capacity` samples (rounded up to a
    /// power of two, at least 4).
    pub fn new(capacity: usize) -> Self {
        let cap = capacity.max(4).next_power_of_two();
        let zeros = || (0..cap).map(|_| AtomicU64::new(0)).collect();
        Self(Arc::new(Ring {
            time: zeros(),
            value: zeros(),
            mask: cap - 1,
            lo: AtomicUsize::new(0),
            hi: AtomicUsize::new(0),
            done: AtomicBool::new(false),
            underrun: AtomicBool::new(false),
            range: [
                AtomicU64::new(f64::NAN.to_bits()),
                AtomicU64::new(f64::NAN.to_bits()),
            ],
        }))
    }

    #[inline]
    fn t_at(&self, g: usize) -> f64 {
        f64::from_bits(self.0.time[g & self.0.mask].load(Relaxed))
    }

    #[inline]
    fn v_at(&self, g: usize) -> f64 {
        f64::from_bits(self.0.value[g & self.0.mask].load(Relaxed))
    }

    /// Samples the window can still take.
    pub fn free(&self) -> usize {
        self.0.time.len() - self.len()
    }

    /// Samples held.
    pub fn len(&self) -> usize {
        self.0.hi.load(Relaxed) - self.0.lo.load(Relaxed)
    }

    /// Whether no sample is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends a sample (its time after the last one's); `false` when the
    /// window is full or the record was finished.
    pub fn push(&self, t: f64, v: f64) -> bool {
        if self.free() == 0 || self.0.done.load(Relaxed) {
            return false;
        }
        let hi = self.0.hi.load(Relaxed);
        self.0.time[hi & self.0.mask].store(t.to_bits(), Relaxed);
        self.0.value[hi & self.0.mask].store(v.to_bits(), Relaxed);
        self.0.hi.store(hi + 1, Relaxed);
        true
    }

    /// The record has no more samples: times after the last are held.
    pub fn finish(&self) {
        self.0.done.store(true, Relaxed);
    }

    /// Whether the record's last sample has been pushed.
    pub fn finished(&self) -> bool {
        self.0.done.load(Relaxed)
    }

    /// The time of the last sample held.
    pub fn last_time(&self) -> Option<f64> {
        let (lo, hi) = (self.0.lo.load(Relaxed), self.0.hi.load(Relaxed));
        (hi > lo).then(|| self.t_at(hi - 1))
    }

    /// The time of the first sample held.
    pub fn first_time(&self) -> Option<f64> {
        let (lo, hi) = (self.0.lo.load(Relaxed), self.0.hi.load(Relaxed));
        (hi > lo).then(|| self.t_at(lo))
    }

    /// Appends the times of the samples held after `t` to `out`.
    pub fn times_after(&self, t: f64, out: &mut Vec<f64>) {
        let (lo, hi) = (self.0.lo.load(Relaxed), self.0.hi.load(Relaxed));
        let mut g = hi;
        while g > lo && self.t_at(g - 1) > t {
            g -= 1;
        }
        out.extend((g..hi).map(|g| self.t_at(g)));
    }

    /// Drops the samples no time `≥ t` needs (all before the one at or
    /// last before `t`).
    pub fn drop_before(&self, t: f64) {
        let (mut lo, hi) = (self.0.lo.load(Relaxed), self.0.hi.load(Relaxed));
        while lo + 1 < hi && self.t_at(lo + 1) <= t {
            lo += 1;
        }
        self.0.lo.store(lo, Relaxed);
    }

    /// Sets the record's smallest and largest value (for components that
    /// size themselves on the command's range, as a table's are read).
    pub fn set_range(&self, min: f64, max: f64) {
        self.0.range[0].store(min.to_bits(), Relaxed);
        self.0.range[1].store(max.to_bits(), Relaxed);
    }

    /// The record's smallest and largest value, when the host set them.
    pub fn range(&self) -> Option<(f64, f64)> {
        let g = |i: usize| f64::from_bits(self.0.range[i].load(Relaxed));
        (!g(0).is_nan()).then(|| (g(0), g(1)))
    }

    /// Whether a value was asked for outside the window (see the module doc).
    pub fn underrun(&self) -> bool {
        self.0.underrun.load(Relaxed)
    }

    fn flag(&self) {
        self.0.underrun.store(true, Relaxed);
    }

    /// The interval `g` (global index) with `t_g <= t < t_{g+1}`, or the
    /// sample to hold when `t` is outside the samples held.
    #[inline]
    fn locate(&self, t: f64, hint: &Cell<usize>) -> Result<usize, usize> {
        let (lo, hi) = (self.0.lo.load(Relaxed), self.0.hi.load(Relaxed));
        if hi == lo {
            self.flag();
            return Err(lo);
        }
        if t < self.t_at(lo) {
            if lo > 0 {
                self.flag();
            }
            return Err(lo);
        }
        if t >= self.t_at(hi - 1) {
            if t > self.t_at(hi - 1) && !self.finished() {
                self.flag();
            }
            return Err(hi - 1);
        }
        // t_lo <= t < t_{hi-1}: march from the hint, then bisect
        let mut g = hint.get().clamp(lo, hi - 2);
        if !(self.t_at(g) <= t && t < self.t_at(g + 1)) {
            let (mut a, mut b) = if t >= self.t_at(g + 1) {
                (g + 1, hi - 1)
            } else {
                (lo, g)
            };
            // t_a <= t < t_b
            while b - a > 1 {
                let m = a + (b - a) / 2;
                if self.t_at(m) <= t {
                    a = m;
                } else {
                    b = m;
                }
            }
            g = a;
        }
        hint.set(g);
        Ok(g)
    }

    /// The first corner after `t` among the samples held from global index
    /// `from` on where the slope jumps by at least `share` of the record's
    /// range times the shorter interval (the test of
    /// the command source's `kinks` on a whole table), and
    /// the index to resume the scan from. `+∞` when no such corner is held
    /// yet (or the range is not set).
    pub fn next_kink(&self, from: usize, t: f64, share: f64) -> (f64, usize) {
        let range = match self.range() {
            Some((lo, hi)) if hi > lo => hi - lo,
            _ => return (f64::INFINITY, from),
        };
        let (lo, hi) = (self.0.lo.load(Relaxed), self.0.hi.load(Relaxed));
        let mut i = from.max(lo + 1);
        while i + 1 < hi {
            let ti = self.t_at(i);
            if ti > t {
                let (d0, d1) = (ti - self.t_at(i - 1), self.t_at(i + 1) - ti);
                let s0 = (self.v_at(i) - self.v_at(i - 1)) / d0;
                let s1 = (self.v_at(i + 1) - self.v_at(i)) / d1;
                if (s1 - s0).abs() * d0.min(d1) >= share * range {
                    return (ti, i);
                }
            }
            i += 1;
        }
        (f64::INFINITY, i)
    }

    /// The value at `t` (first-order hold).
    #[inline]
    pub fn value_hinted(&self, t: f64, hint: &Cell<usize>) -> f64 {
        match self.locate(t, hint) {
            Err(g) => self.v_at(g),
            Ok(g) => {
                let (t0, t1) = (self.t_at(g), self.t_at(g + 1));
                let (v0, v1) = (self.v_at(g), self.v_at(g + 1));
                v0 + (v1 - v0) * (t - t0) / (t1 - t0)
            }
        }
    }

    /// The slope at `t` (the interval's that starts at `t`; 0 outside).
    #[inline]
    pub fn slope_hinted(&self, t: f64, hint: &Cell<usize>) -> f64 {
        match self.locate(t, hint) {
            Err(_) => 0.0,
            Ok(g) => (self.v_at(g + 1) - self.v_at(g)) / (self.t_at(g + 1) - self.t_at(g)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signal::Signal;
    use proptest::prelude::*;

    proptest! {
        /// Inside its window a streamed table is the whole table, whatever
        /// the hint; outside it, it flags an underrun.
        #[test]
        fn window_is_the_table(t in 0.0f64..60.0, h in 0usize..200, drop in 0.0f64..20.0) {
            let ts: Vec<f64> = (0..200).map(|i| 0.3 * i as f64 + 0.01 * (i % 7) as f64).collect();
            let vs: Vec<f64> = ts.iter().map(|t| (t * 0.7).sin()).collect();
            let whole = Signal::table(ts.clone(), vs.clone()).unwrap();
            let s = StreamedTable::new(64);
            let mut k = 0;
            // fill up to t + 1, dropping behind `drop`
            while k < ts.len() && ts[k] <= t + 1.0 {
                if s.free() == 0 {
                    s.drop_before(drop.min(t));
                }
                if !s.push(ts[k], vs[k]) {
                    break;
                }
                k += 1;
            }
            if k == ts.len() {
                s.finish();
            }
            s.drop_before(drop.min(t));
            let hint = Cell::new(h);
            let got = s.value_hinted(t, &hint);
            let want = whole.value(t);
            let inside = s.last_time().is_some_and(|l| l >= t || s.finished());
            if inside && !s.underrun() {
                prop_assert!((got - want).abs() < 1e-12, "{got} vs {want}");
                let sl = s.slope_hinted(t, &hint);
                let wsl = whole.slope_hinted(t, &Cell::new(0));
                prop_assert!((sl - wsl).abs() < 1e-9);
            } else {
                prop_assert!(s.underrun() || s.is_empty());
            }
        }
    }

    #[test]
    fn held_outside_the_record_and_flags_a_gap() {
        let s = StreamedTable::new(4);
        assert!(s.push(1.0, 10.0) && s.push(2.0, 20.0));
        let h = Cell::new(0);
        assert_eq!(s.value_hinted(0.0, &h), 10.0);
        assert_eq!(s.value_hinted(1.5, &h), 15.0);
        assert!(!s.underrun());
        assert_eq!(s.value_hinted(2.5, &h), 20.0);
        assert!(s.underrun(), "past the window while the record goes on");
        let s = StreamedTable::new(4);
        s.push(1.0, 10.0);
        s.push(2.0, 20.0);
        s.finish();
        assert_eq!(s.value_hinted(2.5, &h), 20.0);
        assert!(!s.underrun(), "held after the record's end");
        assert!(!s.push(3.0, 1.0), "nothing after the end");
    }
}
