//! Where two texts start and end alike: what changed between them.

/// Bytes compared a run at a time, with `memcmp`, before byte by byte.
const COMPARED_RUN: usize = 4096;

/// How many bytes `a` and `b` start with alike.
pub(crate) fn common_prefix(a: &[u8], b: &[u8]) -> usize {
    let len = a.len().min(b.len());
    let mut at = 0;
    while at + COMPARED_RUN <= len && a[at..at + COMPARED_RUN] == b[at..at + COMPARED_RUN] {
        at += COMPARED_RUN;
    }
    at + a[at..len].iter().zip(&b[at..len]).take_while(|(x, y)| x == y).count()
}

/// How many bytes `a` and `b` end with alike.
pub(crate) fn common_suffix(a: &[u8], b: &[u8]) -> usize {
    let len = a.len().min(b.len());
    let (a, b) = (&a[a.len() - len..], &b[b.len() - len..]);
    let mut alike = 0;
    while alike + COMPARED_RUN <= len
        && a[len - alike - COMPARED_RUN..len - alike] == b[len - alike - COMPARED_RUN..len - alike]
    {
        alike += COMPARED_RUN;
    }
    alike + a[..len - alike].iter().rev().zip(b[..len - alike].iter().rev()).take_while(|(x, y)| x == y).count()
}

#[cfg(test)]
mod tests {
    use super::{common_prefix, common_suffix};

    proptest::proptest! {
        /// The run-at-a-time comparisons count what byte by byte does.
        #[test]
        fn common_starts_and_ends_are_counted_exactly(
            shared in proptest::collection::vec(0u8..3, 0..9000),
            a in proptest::collection::vec(0u8..3, 0..30),
            b in proptest::collection::vec(0u8..3, 0..30),
            tail in proptest::collection::vec(0u8..3, 0..9000),
        ) {
            let left: Vec<u8> = [&shared[..], &a, &tail].concat();
            let right: Vec<u8> = [&shared[..], &b, &tail].concat();
            let prefix = left.iter().zip(&right).take_while(|(x, y)| x == y).count();
            let suffix = left.iter().rev().zip(right.iter().rev()).take_while(|(x, y)| x == y).count();
            proptest::prop_assert_eq!(common_prefix(&left, &right), prefix);
            proptest::prop_assert_eq!(common_suffix(&left, &right), suffix);
        }
    }
}
