//! The diff summary of an edit (rungs or lines added, removed and changed), for the
//! `detail` of a program or tag table save.

use std::fmt;

/// How two sequences (of rungs, lines) differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DiffSummary {
    /// Items only in the new sequence.
    pub added: usize,
    /// Items only in the old one.
    pub removed: usize,
    /// Items replaced in place: in each run of differences between two common items,
    /// `min(removed, added)` count as changed and only the rest as added or removed.
    pub changed: usize,
}

impl DiffSummary {
    /// Whether the sequences are equal.
    pub fn is_empty(&self) -> bool {
        *self == DiffSummary::default()
    }
}

impl fmt::Display for DiffSummary {
    /// `1 added, 0 removed, 2 changed`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} added, {} removed, {} changed",
            self.added, self.removed, self.changed
        )
    }
}

/// Above this many cells the longest common subsequence is not computed: the part
/// between the common prefix and suffix then counts as changed in full.
const MAX_CELLS: usize = 4_000_000;

/// Compares `old` and `new` item by item (a longest common subsequence after taking off
/// the common prefix and suffix).
pub fn diff<T: PartialEq>(old: &[T], new: &[T]) -> DiffSummary {
    let prefix = old.iter().zip(new).take_while(|(a, b)| a == b).count();
    let (old, new) = (&old[prefix..], &new[prefix..]);
    let suffix = old
        .iter()
        .rev()
        .zip(new.iter().rev())
        .take_while(|(a, b)| a == b)
        .count();
    let (old, new) = (&old[..old.len() - suffix], &new[..new.len() - suffix]);
    let (n, m) = (old.len(), new.len());
    if n == 0 || m == 0 || n.saturating_mul(m) > MAX_CELLS {
        return hunk(n, m);
    }
    // lcs[i][j]: the longest common subsequence of old[i..] and new[j..].
    let w = m + 1;
    let mut lcs = vec![0u32; (n + 1) * w];
    for i in (0..n).rev() {
        for j in (0..m).rev() {
            lcs[i * w + j] = if old[i] == new[j] {
                lcs[(i + 1) * w + j + 1] + 1
            } else {
                lcs[(i + 1) * w + j].max(lcs[i * w + j + 1])
            };
        }
    }
    let mut total = DiffSummary::default();
    let (mut i, mut j) = (0, 0);
    let (mut removed, mut added) = (0, 0);
    let mut flush = |removed: &mut usize, added: &mut usize| {
        let h = hunk(*removed, *added);
        total.added += h.added;
        total.removed += h.removed;
        total.changed += h.changed;
        *removed = 0;
        *added = 0;
    };
    while i < n || j < m {
        if i < n && j < m && old[i] == new[j] {
            flush(&mut removed, &mut added);
            i += 1;
            j += 1;
        } else if j < m && (i == n || lcs[i * w + j + 1] >= lcs[(i + 1) * w + j]) {
            added += 1;
            j += 1;
        } else {
            removed += 1;
            i += 1;
        }
    }
    flush(&mut removed, &mut added);
    total
}

fn hunk(removed: usize, added: usize) -> DiffSummary {
    let changed = removed.min(added);
    DiffSummary {
        added: added - changed,
        removed: removed - changed,
        changed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(old: &str, new: &str) -> (usize, usize, usize) {
        let o: Vec<char> = old.chars().collect();
        let n: Vec<char> = new.chars().collect();
        let s = diff(&o, &n);
        (s.added, s.removed, s.changed)
    }

    #[test]
    fn summaries() {
        assert_eq!(d("abc", "abc"), (0, 0, 0));
        assert_eq!(d("", "abc"), (3, 0, 0));
        assert_eq!(d("abc", ""), (0, 3, 0));
        assert_eq!(d("abc", "abXc"), (1, 0, 0));
        assert_eq!(d("abc", "ac"), (0, 1, 0));
        assert_eq!(d("abc", "aXc"), (0, 0, 1));
        assert_eq!(d("abcdef", "aXcdYZf"), (1, 0, 2));
        assert_eq!(d("abcd", "dabc"), (1, 1, 0));
        assert!(diff::<u8>(&[], &[]).is_empty());
        assert_eq!(
            diff(&[1, 2, 3], &[1, 5, 3]).to_string(),
            "0 added, 0 removed, 1 changed"
        );
    }

    /// added - removed is always the change in length, and nothing is counted twice.
    #[test]
    fn counts_are_consistent() {
        let words = ["abc", "", "aaaa", "abcabc", "cab", "xyz", "bca"];
        for o in words {
            for n in words {
                let (a, r, c) = d(o, n);
                assert_eq!(
                    a as isize - r as isize,
                    n.len() as isize - o.len() as isize,
                    "{o} → {n}"
                );
                assert!(r + c <= o.len() && a + c <= n.len(), "{o} → {n}");
            }
        }
    }
}
