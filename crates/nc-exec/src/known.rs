//! Values a static reading may not know: the checker walks a program over
//! partly unknown state, the executor over known state, with the same types.

/// A value that may not be known statically.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Known<T> {
    Unknown,
    Is(T),
}

impl<T> Known<T> {
    pub fn known(self) -> Option<T> {
        match self {
            Known::Is(value) => Some(value),
            Known::Unknown => None,
        }
    }
}
