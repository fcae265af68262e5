//! The workbench's undo and redo steps, bounded by their count and by their bytes: each step
//! is a whole hypothesis (the parameter text and every overrides row so far), so 200 steps of
//! a hypothesis with a long overrides table held 0.28 MiB an edit without bound (16 pages
//! making lot edits took the server from 112 to 546 MiB in 1,500 edits: issue 74). The
//! oldest steps give way first.

use std::collections::VecDeque;

use super::Hypothesis;

/// Steps kept at most, each way.
pub const MAX_STEPS: usize = 200;
/// Bytes of text kept at most, each way (a step counts its text and its rows' text).
pub const MAX_BYTES: usize = 32 << 20;
/// What a row costs beyond its text: the struct and the three strings' heads.
const ROW_OVERHEAD: usize = 96;

/// A stack of hypotheses, newest last, within [`MAX_STEPS`] and [`MAX_BYTES`].
#[derive(Debug, Default)]
pub struct Steps {
    items: VecDeque<(Hypothesis, usize)>,
    bytes: usize,
}

impl Steps {
    /// Puts `h` on top; the oldest steps go while the stack is over a bound (the newest is
    /// always kept, whatever its size).
    pub fn push(&mut self, h: Hypothesis) {
        let size = size_of(&h);
        self.items.push_back((h, size));
        self.bytes += size;
        while self.items.len() > 1 && (self.items.len() > MAX_STEPS || self.bytes > MAX_BYTES) {
            if let Some((_, old)) = self.items.pop_front() {
                self.bytes -= old;
            }
        }
    }

    /// The newest step, taken off.
    pub fn pop(&mut self) -> Option<Hypothesis> {
        let (h, size) = self.items.pop_back()?;
        self.bytes -= size;
        Some(h)
    }

    pub fn clear(&mut self) {
        self.items.clear();
        self.bytes = 0;
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// The bytes the steps hold, as counted.
    #[cfg(test)]
    pub fn bytes(&self) -> usize {
        self.bytes
    }
}

/// The bytes a hypothesis holds: its text, and each row's text and overhead.
pub fn size_of(h: &Hypothesis) -> usize {
    let rows: usize = (h.rows.iter())
        .map(|o| o.lot.len() + o.field.len() + o.value.len() + ROW_OVERHEAD)
        .sum();
    h.text.len() + rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use edo_city::input::overrides::Override;

    fn with_rows(n: usize, width: usize) -> Hypothesis {
        Hypothesis {
            text: format!("seed = {n}\n"),
            rows: (0..n)
                .map(|i| Override {
                    lot: i.to_string(),
                    field: "mtype".into(),
                    value: "x".repeat(width),
                    row: i + 2,
                })
                .collect(),
        }
    }

    #[test]
    fn the_steps_stay_within_their_count_and_their_bytes() {
        let mut s = Steps::default();
        for n in 0..500 {
            s.push(with_rows(0, n));
        }
        assert_eq!(s.len(), MAX_STEPS);
        assert_eq!(s.pop().unwrap().rows.len(), 0);
        // A hypothesis of 10,000 rows of 1 KB: 33 of them are over the bound.
        let mut s = Steps::default();
        for n in 0..40 {
            let mut h = with_rows(10_000, 1000);
            h.text = format!("seed = {n}\n");
            s.push(h);
            assert!(s.bytes() <= MAX_BYTES, "{}", s.bytes());
        }
        assert!(s.len() < 40 && s.len() > 1, "{}", s.len());
        assert_eq!(s.pop().unwrap().text, "seed = 39\n", "the newest stays");
        // One step over the bound alone is still kept: undo must always go back one.
        let mut s = Steps::default();
        s.push(with_rows(40_000, 1000));
        assert_eq!(s.len(), 1);
        let counted = s.bytes();
        assert!(counted > MAX_BYTES);
        s.pop();
        assert_eq!((s.len(), s.bytes()), (0, 0));
    }
}
