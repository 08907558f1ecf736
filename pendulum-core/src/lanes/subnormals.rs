//! Single-precision kernels whose numbers fall below `f32`'s normal range.
//!
//! The Jacobians' `G = w·V A⁻¹` decays along the chain away from its row: in chains of 100
//! links a sixth to a third of the entries (and more of the numbers on the way) fall below
//! `f32`'s normal range, 1.2e-38 (`tests/tests/single_precision.rs` prints the share), and
//! every operation on a subnormal number takes a microcode assist on this machine's CPUs. The `f32` Jacobians at n = 100 ran slower than
//! the `f64` ones (`docs/ensembles.md`). Flushed to zero they lose nothing the `f32`
//! results can hold (their error against `f64` is of order 1e-6 of the largest entry).

/// While alive, the current thread's SSE/AVX arithmetic flushes subnormal results to zero
/// and reads subnormal inputs as zero (MXCSR's FTZ and DAZ bits); dropped, the thread's
/// previous mode comes back. Put it first in a kernel that only stores its results in
/// memory (the assembly that sets the mode may read and write memory, so no load moves
/// before it and no store after it). Not on other architectures: a no-op there.
pub(crate) struct FlushSubnormals {
    #[cfg(target_arch = "x86_64")]
    saved: u32,
}

/// MXCSR's flush-to-zero (bit 15) and denormals-are-zero (bit 6).
#[cfg(target_arch = "x86_64")]
const FTZ_DAZ: u32 = 0x8040;

impl FlushSubnormals {
    #[inline(always)]
    pub(crate) fn new() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            let mut saved = 0u32;
            // SAFETY: `stmxcsr` writes the four bytes of `saved`; `ldmxcsr` reads four bytes
            // of a valid MXCSR value (the saved one with two mode bits set).
            unsafe {
                std::arch::asm!("stmxcsr [{}]", in(reg) &mut saved, options(nostack, preserves_flags));
                let flushed = saved | FTZ_DAZ;
                std::arch::asm!("ldmxcsr [{}]", in(reg) &flushed, options(nostack, preserves_flags));
            }
            Self { saved }
        }
        #[cfg(not(target_arch = "x86_64"))]
        Self {}
    }
}

impl Drop for FlushSubnormals {
    #[inline(always)]
    fn drop(&mut self) {
        // SAFETY: restores the value `new` read from MXCSR.
        #[cfg(target_arch = "x86_64")]
        unsafe {
            std::arch::asm!("ldmxcsr [{}]", in(reg) &self.saved, options(nostack, preserves_flags));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subnormals_flush_while_the_guard_lives_and_not_after() {
        let tiny = std::hint::black_box(1e-38f32);
        let scale = std::hint::black_box(0.01f32);
        assert!((tiny * scale).is_subnormal());
        {
            let _flush = FlushSubnormals::new();
            let product = std::hint::black_box(tiny) * std::hint::black_box(scale);
            #[cfg(target_arch = "x86_64")]
            assert_eq!(std::hint::black_box(product), 0.0);
            #[cfg(not(target_arch = "x86_64"))]
            assert!(product.is_subnormal());
        }
        assert!((std::hint::black_box(tiny) * std::hint::black_box(scale)).is_subnormal());
    }
}
