//! Values made on their first use and kept, where making one can fail.
//!
//! `OnceLock::get_or_try_init` and `OnceCell::get_or_try_init` would say this, but are not
//! stable. Two threads asking a `OnceLock` at once may both make the value; the first stored is
//! kept and the other dropped, so a value must be the same whoever makes it and making it must
//! have no other effect. No lock is held while it is made, which lets the maker read other
//! values made once (a table's grids read its bases) without a lock order to keep.

use std::cell::OnceCell;
use std::sync::OnceLock;

/// A cell whose value is made by the first reader that asks, if it can be.
pub(crate) trait TryOnce<T> {
    /// The value, made by `make` if there is none yet; `make`'s error otherwise, the cell left
    /// empty for a later reader to try again.
    fn get_or_try<E>(&self, make: impl FnOnce() -> Result<T, E>) -> Result<&T, E>;
}

impl<T> TryOnce<T> for OnceLock<T> {
    fn get_or_try<E>(&self, make: impl FnOnce() -> Result<T, E>) -> Result<&T, E> {
        if let Some(value) = self.get() {
            return Ok(value);
        }
        let value = make()?;
        Ok(self.get_or_init(|| value))
    }
}

impl<T> TryOnce<T> for OnceCell<T> {
    fn get_or_try<E>(&self, make: impl FnOnce() -> Result<T, E>) -> Result<&T, E> {
        if let Some(value) = self.get() {
            return Ok(value);
        }
        let value = make()?;
        Ok(self.get_or_init(|| value))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_make_leaves_the_cell_for_the_next_reader() {
        let lock = OnceLock::new();
        assert_eq!(lock.get_or_try(|| Err::<u32, _>("no")), Err("no"));
        assert_eq!(lock.get_or_try(|| Ok::<_, &str>(3)), Ok(&3));
        // Made once: a later maker is not called.
        assert_eq!(lock.get_or_try(|| Err::<u32, _>("again")), Ok(&3));
        let cell = OnceCell::new();
        assert_eq!(cell.get_or_try(|| Err::<u32, _>("no")), Err("no"));
        assert_eq!(cell.get_or_try(|| Ok::<_, &str>(5)), Ok(&5));
        assert_eq!(cell.get_or_try(|| Err::<u32, _>("again")), Ok(&5));
    }
}
