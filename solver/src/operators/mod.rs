//! Layer 4, kernels and operators: planned FFTs, the DC-FFT operator and its
//! coarse levels, the stresses below the surface (their own depth kernels),
//! and a kernel's identity, store and build. Knows no contact conditions.

pub mod fft2;
pub mod kernels;
pub mod multilevel;
pub mod operator;
pub mod stress;
