//! Searching sorted times from where the last search ended: the
//! interpolations of a pass over a drive ([`crate::reference::Reference::state_at`],
//! the delay estimation's integrals) ask for times that mostly increase, so
//! a search that starts at the previous answer takes a step or two instead
//! of a binary search over the whole series (`Integral::at` and
//! `Reference::state_at` were 14 % and 9 % of `calibrate`'s profile).

/// The number of the sorted keys `key(0) ≤ … ≤ key(n − 1)` that are `≤ t`:
/// what `slice::partition_point(|k| k <= t)` returns, found by galloping
/// from `hint` (any value: the answer does not depend on it, only the time
/// taken). For keys that are not sorted the answer is some partition point,
/// as for `partition_point`.
pub(crate) fn partition_from(n: usize, key: impl Fn(usize) -> f64, t: f64, hint: usize) -> usize {
    let h = hint.min(n);
    let (mut lo, mut hi) = if h < n && key(h) <= t {
        // Forward: key(lo − 1) ≤ t; gallop until a key above t (or the end).
        let (mut lo, mut step) = (h + 1, 1);
        loop {
            let probe = lo + step - 1;
            if probe >= n {
                break (lo, n);
            }
            if key(probe) > t {
                break (lo, probe);
            }
            lo = probe + 1;
            step *= 2;
        }
    } else if h > 0 && key(h - 1) > t {
        // Backward: key(hi) > t; gallop down until a key at or below t.
        let (mut hi, mut step) = (h - 1, 1);
        loop {
            if step > hi {
                break (0, hi);
            }
            let probe = hi - step;
            if key(probe) <= t {
                break (probe + 1, hi);
            }
            hi = probe;
            step *= 2;
        }
    } else {
        return h;
    };
    // Invariant: every key before lo is ≤ t, key(hi) > t or hi == n.
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if key(mid) <= t {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equal to `partition_point` from every hint, on sorted keys with
    /// repeats, at the keys, between them and outside them.
    #[test]
    fn equals_partition_point_from_any_hint() {
        // A seeded xorshift: keys on a 0.5 grid, so that many repeat.
        let mut state = 30u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 40) as f64 * 0.5
        };
        for n in [0usize, 1, 2, 3, 7, 64, 200] {
            let mut keys: Vec<f64> = (0..n).map(|_| next()).collect();
            keys.sort_by(f64::total_cmp);
            for q in 0..90 {
                let t = q as f64 * 0.25 - 1.0;
                let want = keys.partition_point(|&k| k <= t);
                for hint in 0..=n + 2 {
                    assert_eq!(
                        partition_from(n, |i| keys[i], t, hint),
                        want,
                        "n {n} t {t} hint {hint}"
                    );
                }
            }
        }
    }
}
