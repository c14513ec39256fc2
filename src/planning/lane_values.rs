//! The lanes in memory: [`N`] f32 values stored together ([`L`], 32-byte aligned, one
//! robot configuration per lane) and the lane masks ([`Mask`], [`ALL`]) the SIMD tokens
//! and the lane geometry share.

/// Number of lanes.
pub const N: usize = 8;

/// Eight f32 values in memory, one per configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct L(pub [f32; N]);

/// A lane mask: bit `i` set when lane `i` is true.
pub type Mask = u32;

/// Mask with all lanes set.
pub const ALL: Mask = (1 << N) - 1;

impl L {
    /// All lanes `x`.
    pub fn splat(x: f32) -> L {
        L([x; N])
    }
}
