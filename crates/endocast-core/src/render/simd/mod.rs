//! Every `std::arch` intrinsic and every `unsafe` block of the renderer, behind safe functions.
//!
//! The rest of `render` calls only safe code; the workspace denies `unsafe_code` and this module
//! alone allows it. Each batch here repeats its scalar twin operation for operation (no fused
//! multiply-add, the same comparisons, the same order), so it gives the same bits; the render
//! tests compare both paths lane by lane.
//!
//! - [`rays4`]: ray set-up for four pixels of a row (AVX2, `f64`);
//! - `cells8`: the exact isosurface search (the cell walk) for eight rays, one per lane (AVX2);
//! - [`packet`]: the isosurface search and its refinement for eight rays, one per lane (AVX2);
//! - [`sample`]: eight trilinear samples by gathers (AVX2);
//! - [`sse`]: small SSE/SSE2 batches on eight values (crossing sides, transfer-table lookups)
//!   with their scalar forms on other targets;
//! - `unchecked`: the scalar sampler's read of a 2×2×2 cell with one bounds check;
//! - [`with_avx2`]: plain Rust (loops over fixed lanes that LLVM vectorises) compiled for AVX2
//!   where the CPU has it: the look's deferred stage.
//!
//! # Safety argument
//!
//! Two kinds of `unsafe` live here, each with a `// SAFETY:` note where it is used:
//!
//! - Calling a `#[target_feature(enable = "avx2")]` function from code compiled without AVX2.
//!   That is sound only on a CPU with AVX2, which [`Avx2`] proves: a zero-sized token whose only
//!   constructor, [`Avx2::detect`], returns one where `is_x86_feature_detected!("avx2")` says so.
//!   Every entry point into the AVX2 code is a safe method that takes the token, so safe code
//!   cannot reach AVX2 instructions without having detected them. SSE and SSE2 are part of the
//!   x86-64 baseline every build targets and need no token.
//! - Raw memory access: unaligned vector loads and stores to arrays of exactly the lanes' size,
//!   gathers whose every lane index is clamped or proven inside its slice, `mem::zeroed` of
//!   plain vector structs, and unchecked slice reads whose bounds follow from a check made just
//!   before (each note says which).

#![allow(unsafe_code)]

#[cfg(target_arch = "x86_64")]
mod cells8;
#[cfg(target_arch = "x86_64")]
pub(super) mod packet;
#[cfg(target_arch = "x86_64")]
pub(super) mod rays4;
#[cfg(target_arch = "x86_64")]
mod sample;
pub(super) mod sse;
mod unchecked;

#[cfg(target_arch = "x86_64")]
use super::{
    cell_walk::CellWalk,
    ray_task::{Bracket, RayTask},
    voxel_grid::{Lanes, SampleGrid, VoxelGrid},
};

/// Proof that this CPU runs AVX2 (and so the AVX2 batches): zero-sized, `Copy`, and made only by
/// [`Avx2::detect`]. Code that holds one calls the AVX2 paths through its safe methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))] // never made there
pub(crate) struct Avx2(());

impl Avx2 {
    /// The token where the CPU has AVX2 (detected at run time, cached by `std`); `None`
    /// elsewhere, and always on targets other than x86-64.
    #[inline]
    pub(crate) fn detect() -> Option<Self> {
        #[cfg(target_arch = "x86_64")]
        {
            std::is_x86_feature_detected!("avx2").then_some(Self(()))
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            None
        }
    }
}

/// Runs `f` with AVX2 enabled for the code inlined into it (`#[inline(always)]` functions and
/// closures: loops over fixed lanes then vectorise eight `f32` wide) where the CPU has AVX2,
/// else as compiled for the baseline. No fused multiply-add is enabled, and LLVM reorders no
/// floating-point operation, so both give the same bits.
#[inline(always)]
pub(crate) fn with_avx2<R>(f: impl FnOnce() -> R) -> R {
    match Avx2::detect() {
        #[cfg(target_arch = "x86_64")]
        Some(_) => {
            // SAFETY: the token exists, so the CPU has AVX2.
            unsafe { avx2_context(f) }
        }
        _ => f(),
    }
}

/// `f()` in a function compiled for AVX2, so that what is inlined into it is too.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn avx2_context<R>(f: impl FnOnce() -> R) -> R {
    f()
}

#[cfg(target_arch = "x86_64")]
impl Avx2 {
    /// The rays of pixels `x0 .. x0 + 4` of row `y` ([`rays4::RaySetup::rays4`]).
    #[inline]
    pub(crate) fn rays4(
        self,
        setup: &rays4::RaySetup,
        x0: usize,
        y: usize,
        late: Option<&rays4::LateStarts>,
    ) -> [Option<rays4::LaneRay>; 4] {
        // SAFETY: the token exists, so the CPU has AVX2.
        unsafe { setup.rays4(x0, y, late) }
    }

    /// [`packet::search8`]: the first crossings of `iso` of up to eight rays.
    #[inline]
    pub(crate) fn search8(
        self,
        sampler: &VoxelGrid<'_>,
        active: Option<&[u64]>,
        iso: f32,
        tasks: &mut [RayTask],
        rising: [bool; 8],
    ) -> [Option<Bracket>; 8] {
        // SAFETY: the token exists, so the CPU has AVX2.
        unsafe { packet::search8(sampler, active, iso, tasks, rising) }
    }

    /// [`cells8::first_hits8`]: the exact first crossings of up to eight rays, each from its
    /// side `(rising, before)`.
    #[inline]
    pub(crate) fn first_hits8(
        self,
        walk: &CellWalk<'_>,
        tasks: &[RayTask],
        sides: [(bool, bool); 8],
    ) -> [Option<f32>; 8] {
        // SAFETY: the token exists, so the CPU has AVX2.
        unsafe { cells8::first_hits8(walk, tasks, sides) }
    }

    /// [`packet::refine8`]: `steps` bisection steps of up to eight rays' brackets.
    #[inline]
    pub(crate) fn refine8(
        self,
        sampler: &VoxelGrid<'_>,
        iso: f32,
        tasks: &mut [RayTask],
        steps: u32,
    ) {
        // SAFETY: the token exists, so the CPU has AVX2.
        unsafe { packet::refine8(sampler, iso, tasks, steps) }
    }

    /// Samples `n .. n + 8` of `grid`.
    #[inline]
    pub(crate) fn grid8(self, sampler: &VoxelGrid<'_>, grid: &SampleGrid, n: i32) -> Lanes {
        // SAFETY: the token exists, so the CPU has AVX2.
        unsafe { sample::grid8(sampler, grid, n) }
    }

    /// The values at eight positions given as their x, y and z lanes.
    #[inline]
    pub(crate) fn points8(self, sampler: &VoxelGrid<'_>, xyz: [&Lanes; 3]) -> Lanes {
        // SAFETY: the token exists, so the CPU has AVX2.
        unsafe { sample::points8(sampler, xyz) }
    }

    /// The values at `line.at(t[k])` for the eight distances `t`.
    #[inline]
    pub(crate) fn along8(self, sampler: &VoxelGrid<'_>, line: &SampleGrid, t: &Lanes) -> Lanes {
        // SAFETY: the token exists, so the CPU has AVX2.
        unsafe { sample::along8(sampler, line, t) }
    }
}
