//! What the host and a kernel or shader stage agree on, written once on the Rust side so that it
//! can be checked against the committed SPIR-V (`tests/interfaces.rs` reflects every module):
//! the descriptor sets, the push-constant block, the structs of its buffers and, for a vertex
//! stage, its inputs.
//!
//! Each `#[repr(C)]` type that mirrors a GLSL block states its layout with [`glsl_struct!`],
//! which asserts at compile time that the Rust type has the GLSL's size and member offsets.

use super::graphics::Attribute;
use super::pipeline::BindingKind;

/// A GLSL struct or block as a Rust type lays it out: its name in the GLSL, its size in bytes,
/// and each member's name and byte offset (std430 for buffers and push constants).
#[derive(Clone, Copy, Debug)]
pub struct GlslStruct {
    pub name: &'static str,
    pub size: usize,
    pub members: &'static [(&'static str, usize)],
}

/// A Rust type with the layout of a GLSL struct.
pub trait GlslLayout {
    const GLSL: GlslStruct;
}

/// Declares that a `#[repr(C)]` type mirrors the GLSL struct `glsl`: asserts at compile time that
/// its size and each named field's offset are the GLSL's, and implements [`GlslLayout`] so that
/// the interface test can compare the same numbers with the SPIR-V.
///
/// ```ignore
/// glsl_struct!(FinalizePush as "Finalize", 20 bytes { exposure_scale @ 0, tonemap @ 4, … });
/// ```
#[macro_export]
macro_rules! glsl_struct {
    ($ty:ty as $glsl:literal, $size:literal bytes { $($field:ident @ $offset:literal),* $(,)? }) => {
        const _: () = assert!(::std::mem::size_of::<$ty>() == $size, concat!("size of ", stringify!($ty)));
        $(
            const _: () = assert!(
                ::std::mem::offset_of!($ty, $field) == $offset,
                concat!("offset of ", stringify!($ty), "::", stringify!($field))
            );
        )*
        impl $crate::gpu::interface::GlslLayout for $ty {
            const GLSL: $crate::gpu::interface::GlslStruct = $crate::gpu::interface::GlslStruct {
                name: $glsl,
                size: $size,
                members: &[$((stringify!($field), $offset)),*],
            };
        }
    };
}

/// One SPIR-V module's interface, as the Rust side builds its pipeline.
#[derive(Clone, Copy, Debug)]
pub struct Interface {
    /// The GLSL file, `glsl/<file>`.
    pub file: &'static str,
    pub spirv: &'static [u8],
    /// Set `s`, binding `b` has kind `sets[s][b]`.
    pub sets: &'static [&'static [BindingKind]],
    /// The push-constant block, if the module declares one.
    pub push: Option<GlslStruct>,
    /// The structs its buffers hold, each checked where the module declares it.
    pub structs: &'static [GlslStruct],
    /// A vertex stage's inputs.
    pub vertex_inputs: &'static [Attribute],
}

impl Interface {
    /// A compute kernel's interface, with no buffer structs named.
    pub const fn compute(
        kernel: &super::shaders::Kernel,
        sets: &'static [&'static [BindingKind]],
        push: Option<GlslStruct>,
    ) -> Interface {
        Interface { file: kernel.file, spirv: kernel.spirv, sets, push, structs: &[], vertex_inputs: &[] }
    }

    /// Bytes of push constants, for the pipeline layout.
    pub const fn push_size(&self) -> u32 {
        match self.push {
            Some(push) => push.size as u32,
            None => 0,
        }
    }
}
