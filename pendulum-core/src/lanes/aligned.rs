//! A growable array whose first element starts on a cache line (64 bytes).
//!
//! The batches keep their lanes in arrays of 64-byte `Lanes<8>` (one AVX-512 register each)
//! or 32-byte `Lanes<4>`. In a `Vec` they start wherever the allocator puts them, 16 bytes
//! into a line as often as not, and then every register load and store of them touches
//! two cache lines. On the Intel Xeon of `docs/ensembles.md` that cost a 3D batch call at
//! n = 100 a fifth of its time; on AMD's Zen 5 much less.

use std::fmt;
use std::marker::PhantomData;
use std::mem::{MaybeUninit, align_of, size_of};
use std::ops::{Deref, DerefMut};

/// One cache line of storage.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Line(MaybeUninit<[u8; 64]>);

/// `len` values of `T` from a 64-byte boundary, used as a slice (`Deref`).
#[derive(Clone)]
pub(crate) struct Aligned<T: Copy> {
    /// The storage: at least `len · size_of::<T>()` bytes.
    lines: Vec<Line>,
    /// Values `0..len` are written (the invariant every read relies on).
    len: usize,
    _values: PhantomData<T>,
}

impl<T: Copy> Aligned<T> {
    /// `T` fits the storage's alignment, and is not zero-sized.
    const FITS: () = assert!(align_of::<T>() <= 64 && size_of::<T>() > 0);

    /// An empty array.
    pub(crate) fn new() -> Self {
        Self { lines: Vec::new(), len: 0, _values: PhantomData }
    }

    /// `len` copies of `value`.
    pub(crate) fn filled(value: T, len: usize) -> Self {
        let mut array = Self::new();
        array.resize(len, value);
        array
    }

    /// `len` values: those kept, then copies of `value` (as `Vec::resize`).
    pub(crate) fn resize(&mut self, len: usize, value: T) {
        let () = Self::FITS;
        if len > self.len {
            let lines = (len * size_of::<T>()).div_ceil(size_of::<Line>());
            if lines > self.lines.len() {
                // Moves the bytes of the values written so far along with the lines.
                self.lines.resize(lines, Line(MaybeUninit::uninit()));
            }
            let first = self.lines.as_mut_ptr().cast::<T>();
            for i in self.len..len {
                // SAFETY: value `i` lies within the lines (`lines · 64 ≥ len · size_of::<T>()`),
                // aligned (`Line`'s 64 bytes are a multiple of `align_of::<T>()`, `FITS`).
                unsafe { first.add(i).write(value) };
            }
        }
        self.len = len;
    }
}

impl<T: Copy> Default for Aligned<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Copy> Deref for Aligned<T> {
    type Target = [T];

    #[inline(always)]
    fn deref(&self) -> &[T] {
        // SAFETY: values `0..len` are written (`resize`), in storage aligned for `T`; an
        // empty `Vec`'s pointer is dangling but aligned to 64, which serves `len = 0`.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<T>(), self.len) }
    }
}

impl<T: Copy> DerefMut for Aligned<T> {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [T] {
        // SAFETY: as in `deref`, borrowed mutably through `self`.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<T>(), self.len) }
    }
}

impl<'a, T: Copy> IntoIterator for &'a Aligned<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<'a, T: Copy> IntoIterator for &'a mut Aligned<T> {
    type Item = &'a mut T;
    type IntoIter = std::slice::IterMut<'a, T>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter_mut()
    }
}

impl<T: Copy> FromIterator<T> for Aligned<T> {
    fn from_iter<I: IntoIterator<Item = T>>(values: I) -> Self {
        let values: Vec<T> = values.into_iter().collect();
        let mut array = Self::new();
        if let Some(&first) = values.first() {
            array.resize(values.len(), first);
            array.copy_from_slice(&values);
        }
        array
    }
}

impl<T: Copy + fmt::Debug> fmt::Debug for Aligned<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        (**self).fmt(f)
    }
}

impl<T: Copy + PartialEq> PartialEq for Aligned<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::Lanes;

    #[test]
    fn values_start_on_a_cache_line_and_survive_growth() {
        let mut a = Aligned::filled(Lanes([1.5; 8]), 3);
        assert_eq!(a.as_ptr() as usize % 64, 0);
        a[2] = Lanes([2.0; 8]);
        a.resize(1000, Lanes([-3.0; 8]));
        assert_eq!(a.as_ptr() as usize % 64, 0);
        assert_eq!((a.len(), a[0], a[2], a[999]), (1000, Lanes([1.5; 8]), Lanes([2.0; 8]), Lanes([-3.0; 8])));
        a.resize(1, Lanes([0.0; 8]));
        a.resize(2, Lanes([4.0; 8]));
        assert_eq!(&a[..], &[Lanes([1.5; 8]), Lanes([4.0; 8])]);
        let odd: Aligned<[f64; 3]> = (0..5).map(|i| [i as f64; 3]).collect();
        assert_eq!(odd.as_ptr() as usize % 64, 0);
        assert_eq!(odd[4], [4.0; 3]);
        assert_eq!(odd.clone(), odd);
        assert!(Aligned::<f64>::default().is_empty());
    }
}
