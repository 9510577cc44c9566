//! The reorder window: messages from several topics released in header-stamp
//! order once no earlier one can still come (within the window), late ones
//! refused and counted, never applied out of order.

use std::collections::BTreeMap;

/// A time as a totally ordered key (finite times only are pushed).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Key {
    t_s: f64,
    rank: u8,
    seq: u64,
}

impl Eq for Key {}

impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Key {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.t_s
            .total_cmp(&other.t_s)
            .then(self.rank.cmp(&other.rank))
            .then(self.seq.cmp(&other.seq))
    }
}

/// Items waiting for their turn. An item of time `t` is released once an item
/// of time `t + window_s` or later has arrived (or at the end, [`Reorder::drain`]);
/// items of equal times leave in `rank` order (the order of
/// [`deadreckon_core::event::Event`]'s ties: wheels, gyro, speed, steering,
/// GNSS), then in arrival order. An item older than one already released is
/// late: [`Reorder::push`] gives it back.
#[derive(Debug, Clone)]
pub struct Reorder<T> {
    window_s: f64,
    waiting: BTreeMap<Key, T>,
    newest_s: f64,
    released_s: f64,
    seq: u64,
}

impl<T> Reorder<T> {
    /// A window of `window_s` seconds of stamp time (0: in arrival order,
    /// anything older than the newest refused).
    pub fn new(window_s: f64) -> Self {
        Reorder {
            window_s,
            waiting: BTreeMap::new(),
            newest_s: f64::NEG_INFINITY,
            released_s: f64::NEG_INFINITY,
            seq: 0,
        }
    }

    /// Takes an item of time `t_s` (finite), or gives it back when it is
    /// late (older than an item already released) or its time is not finite.
    pub fn push(&mut self, t_s: f64, rank: u8, item: T) -> Result<(), T> {
        if !t_s.is_finite() || t_s < self.released_s {
            return Err(item);
        }
        self.newest_s = self.newest_s.max(t_s);
        self.seq += 1;
        self.waiting.insert(
            Key {
                t_s,
                rank,
                seq: self.seq,
            },
            item,
        );
        Ok(())
    }

    /// The oldest item whose window has passed, with its time.
    pub fn pop_ready(&mut self) -> Option<(f64, T)> {
        let (k, _) = self.waiting.first_key_value()?;
        if k.t_s > self.newest_s - self.window_s {
            return None;
        }
        self.pop()
    }

    /// The oldest item, ready or not (at the end of the input).
    pub fn drain(&mut self) -> Option<(f64, T)> {
        self.pop()
    }

    fn pop(&mut self) -> Option<(f64, T)> {
        let (k, item) = self.waiting.pop_first()?;
        self.released_s = k.t_s;
        Some((k.t_s, item))
    }

    /// Items waiting.
    pub fn len(&self) -> usize {
        self.waiting.len()
    }

    /// True when nothing waits.
    pub fn is_empty(&self) -> bool {
        self.waiting.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ready<T>(r: &mut Reorder<T>) -> Vec<T> {
        std::iter::from_fn(|| r.pop_ready().map(|(_, x)| x)).collect()
    }

    #[test]
    fn items_leave_in_time_then_rank_order_once_the_window_has_passed() {
        let mut r = Reorder::new(0.1);
        r.push(1.00, 4, "gnss").unwrap();
        r.push(1.00, 0, "wheel").unwrap();
        r.push(0.98, 1, "gyro").unwrap();
        assert!(
            ready(&mut r).is_empty(),
            "nothing 0.1 s older than 1.00 yet"
        );
        r.push(1.07, 1, "gyro2").unwrap();
        assert!(ready(&mut r).is_empty(), "0.98 + 0.1 > 1.07");
        r.push(1.10, 0, "wheel2").unwrap();
        assert_eq!(ready(&mut r), vec!["gyro", "wheel", "gnss"]);
        assert_eq!(r.len(), 2);
        assert_eq!(
            std::iter::from_fn(|| r.drain().map(|(_, x)| x)).collect::<Vec<_>>(),
            vec!["gyro2", "wheel2"]
        );
    }

    #[test]
    fn an_item_older_than_one_released_is_given_back_never_applied() {
        let mut r = Reorder::new(0.05);
        r.push(2.0, 0, 1).unwrap();
        r.push(2.1, 0, 2).unwrap();
        assert_eq!(r.pop_ready(), Some((2.0, 1)));
        assert_eq!(r.push(1.99, 1, 3), Err(3), "late: 1.99 < 2.0 released");
        assert_eq!(
            r.push(2.0, 4, 4),
            Ok(()),
            "a tie with the released time is in order"
        );
        assert_eq!(r.push(f64::NAN, 0, 5), Err(5));
        assert_eq!(r.drain(), Some((2.0, 4)));
        assert_eq!(r.drain(), Some((2.1, 2)));
        assert!(r.is_empty());
    }

    #[test]
    fn a_zero_window_releases_in_arrival_order() {
        let mut r = Reorder::new(0.0);
        r.push(1.0, 0, 'a').unwrap();
        assert_eq!(r.pop_ready(), Some((1.0, 'a')));
        assert_eq!(r.push(0.5, 0, 'b'), Err('b'));
    }
}
