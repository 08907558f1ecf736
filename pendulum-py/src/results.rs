//! Room for large results, handed to numpy without a copy.
//!
//! A result of hundreds of megabytes (the Jacobians of 10⁴ states of 20 links are 576 MB)
//! is written into fresh pages, and with the kernel's 4 kB pages faulting them in cost more
//! than computing the numbers: numpy itself asks for huge pages on arrays of 4 MB and more
//! (`madvise(MADV_HUGEPAGE)`), and writing 576 MB into such an array took 99 ms here
//! against 280 ms into plain pages (`docs/python.md`). The rooms below ask the same.

/// From this many bytes on, a result's pages are asked to be huge, as numpy asks.
const HUGE_FROM: usize = 1 << 22;

/// `len` zeros, in pages the kernel may make huge (2 MB) where the result is large: fresh
/// from the allocator, untouched until the batch writes them.
pub fn zeros<T: Copy + Default>(len: usize) -> Vec<T> {
    let v = vec![T::default(); len];
    let bytes = len * std::mem::size_of::<T>();
    if bytes >= HUGE_FROM {
        advise_huge(v.as_ptr().cast(), bytes);
    }
    v
}

/// Room in `v` for `times` times the values it holds, in pages the kernel may make huge
/// where that is large (the samples of a long run, appended as they come).
pub fn reserve_times<T>(v: &mut Vec<T>, times: usize) {
    v.reserve_exact(v.len() * times.saturating_sub(1));
    let bytes = v.capacity() * std::mem::size_of::<T>();
    if bytes >= HUGE_FROM {
        advise_huge(v.as_ptr().cast(), bytes);
    }
}

/// Asks the kernel for huge pages over the whole pages of `bytes` bytes from `start`
/// (advice only: where it is refused, or not Linux, the pages stay as they are).
#[cfg(target_os = "linux")]
fn advise_huge(start: *const u8, bytes: usize) {
    let page = 4096;
    let offset = start.align_offset(page);
    if offset < bytes {
        // SAFETY: the range lies inside the allocation of `bytes` bytes from `start`;
        // `madvise` with MADV_HUGEPAGE changes no contents, only how pages are backed.
        unsafe {
            libc::madvise(start.add(offset) as *mut libc::c_void, bytes - offset, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge(_start: *const u8, _bytes: usize) {}
