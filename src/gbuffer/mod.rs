//! The g-buffer: everything the relighter needs per pixel, read from an OpenEXR file or made by
//! the built-in shader-ball scene.
//!
//! The file format (channels, masks and maps, object and mask names, which problems are errors
//! and which are fixed with a warning, compression) is specified in docs/formats.md#g-buffers;
//! other renderers' files are translated into these channels by [`source`]
//! (docs/formats.md#production-renders). [`GBuffer::write`] stores `N.*` (and `V.*`, `T.*` where
//! the g-buffer has them) as float, `A`, masks and maps as half and `objectId` as uint,
//! ZIP-compressed, through a temporary file renamed into place. [`GBuffer::shaderball`] makes the
//! built-in scene (docs/formats.md#the-built-in-scene) without a file, [`GBuffer::sphere`] the
//! built-in orthographic sphere (docs/formats.md#the-built-in-sphere).

pub mod blur;
mod frame;
pub mod gpu;
mod procedural;
mod read;
mod scene;
mod shaderball;
pub mod source;
mod sphere;
mod validate;
mod write;

pub(crate) use frame::orthogonalize;
pub use frame::stable_tangent;
pub use read::Read;
/// Object ids of the built-in scene.
pub use scene::{BALL_ID, PEDESTAL_ID};
pub use source::{SourceOptions, Up};
/// The built-in sphere's object ID and framing.
pub use sphere::{SPHERE_FRAME_HALF_EXTENT, SPHERE_ID};

use crate::visibility::Visibility;
use std::collections::BTreeMap;

/// The largest side `--size` (or a look's `[gbuffer] size`) gives the built-in shader ball:
/// 8192² is a 4 GiB g-buffer, made on the CPU, and above most devices' image limits.
pub const MAX_BUILTIN_SIDE: u32 = 8192;

/// Channel names of the file format.
pub const NORMAL_CHANNELS: [&str; 3] = ["N.X", "N.Y", "N.Z"];
pub const VIEW_CHANNELS: [&str; 3] = ["V.X", "V.Y", "V.Z"];
pub const TANGENT_CHANNELS: [&str; 3] = ["T.X", "T.Y", "T.Z"];
pub const COVERAGE_CHANNEL: &str = "A";
pub const OBJECT_ID_CHANNEL: &str = "objectId";
/// A mask channel is this prefix followed by the mask's name.
pub const MASK_PREFIX: &str = "mask.";
/// A map channel is this prefix followed by the map's name (and `.R`/`.G`/`.B` for a colour).
pub const MAP_PREFIX: &str = "map.";
/// The channel suffixes of a colour map.
pub const COLOR_MAP_CHANNELS: [&str; 3] = ["R", "G", "B"];
/// An object's name is stored in the header attribute with this prefix followed by its ID.
pub const OBJECT_NAME_PREFIX: &str = "objectName.";
/// A visibility channel is this prefix followed by its word's index (`visibility.0` …): 32 bits
/// of the pixel's [`crate::visibility::Visibility`] each, as uint (docs/formats.md#visibility).
pub const VISIBILITY_PREFIX: &str = "visibility.";
/// The full name behind a mask whose channel name had to be shortened or made safe is stored
/// in the header attribute with this prefix followed by the mask's name.
pub const MASK_NAME_PREFIX: &str = "maskName.";
/// The text attribute that records a supersampled g-buffer's factor ([`GBuffer::supersample`]).
pub const SUPERSAMPLE_ATTRIBUTE: &str = "supersample";
/// The largest supersampling factor: 64 g-buffer pixels an output pixel.
pub const MAX_SUPERSAMPLE: u32 = 8;

/// The view vector of a file without `V.*`: an orthographic camera looking down −Z.
pub const DEFAULT_VIEW: [f32; 3] = [0.0, 0.0, 1.0];
/// The normal stored where a pixel is not covered and the file's normal is unusable.
pub const PLACEHOLDER_NORMAL: [f32; 3] = [0.0, 0.0, 1.0];

/// A validated g-buffer: everything the renderer needs, per pixel, row 0 at the top.
///
/// Every per-pixel vector holds `width * height` entries in row-major order. Directions are unit
/// length everywhere, including background pixels, so kernels need no guards.
#[derive(Clone, Debug, PartialEq)]
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    /// Unit world-space shading normal; [`PLACEHOLDER_NORMAL`] where coverage is 0 and the
    /// file's normal is unusable.
    pub normal: Vec<[f32; 3]>,
    /// Unit vector from the surface toward the eye; [`DEFAULT_VIEW`] when the file has no `V.*`.
    /// On background pixels of the shader ball it is minus the camera ray, so the environment
    /// behind the objects can be shown.
    pub view: Vec<[f32; 3]>,
    /// Unit tangent, orthogonal to `normal`: the stored `T.*` after Gram–Schmidt, or the
    /// [`stable_tangent`] of the normal. The bitangent is `cross(normal, tangent)`.
    pub tangent: Vec<[f32; 3]>,
    /// Coverage in \[0,1\]: 0 is background, fractional values antialias silhouettes.
    pub coverage: Vec<f32>,
    /// Object ID; 0 when the file has no `objectId` channel.
    pub object_id: Vec<u32>,
    /// Layer masks in \[0,1\], keyed by name without the `mask.` prefix.
    pub masks: BTreeMap<String, Vec<f32>>,
    /// Parameter map channels in \[0,1\], keyed by channel name without the `map.` prefix
    /// (`baseColor.R`, `rough`); [`GBuffer::maps`] tells colour maps from scalar ones.
    pub maps: BTreeMap<String, Vec<f32>>,
    /// Object names by ID, from the `objectName.<ID>` header attributes.
    pub object_names: BTreeMap<u32, String>,
    /// The full names of masks whose channel names were shortened or made safe (a material's
    /// name as the asset gives it), by mask name, from the `maskName.<mask>` header attributes.
    pub mask_names: BTreeMap<String, String>,
    /// Which world directions each pixel's surface point sees the environment along; `None`
    /// where nothing was stored, and every direction above the horizon is seen.
    pub visibility: Option<Visibility>,
    /// Whether the file carried `V.*`.
    pub has_view: bool,
    /// Whether the file carried `T.*`.
    pub has_tangent: bool,
    /// G-buffer pixels per side of an output pixel: the file was written at this multiple of the
    /// output resolution, and renders relight every pixel, then average each block
    /// (docs/formats.md#supersampled-g-buffers). 1 for a plain g-buffer.
    pub supersample: u32,
}

/// Whether a `width` × `height` g-buffer can be `factor` times its output's resolution on each
/// side: a factor of 1 to [`MAX_SUPERSAMPLE`] that divides both sides.
pub fn check_supersample(factor: u32, width: u32, height: u32) -> Result<(), String> {
    if !(1..=MAX_SUPERSAMPLE).contains(&factor) {
        return Err(format!("a supersampling factor is 1 to {MAX_SUPERSAMPLE}, not {factor}"));
    }
    if width % factor != 0 || height % factor != 0 {
        return Err(format!("{width}x{height} pixels are not a multiple of {factor} on each side"));
    }
    Ok(())
}

/// Whether `name` can name a map in a look: not empty, no spaces around it, no control
/// characters, and without the channel prefix `map.` (which a look leaves out). The g-buffer's
/// map channels whose names fail this are left out of the g-buffer, with a warning.
pub fn check_map_name(name: &str) -> Result<(), String> {
    if name.is_empty() {
        return Err("a map's name must not be empty".into());
    }
    if name.trim() != name {
        return Err(format!("{name:?}: a map's name has no spaces around it"));
    }
    if name.chars().any(char::is_control) {
        return Err(format!("{name:?}: a map's name has no control characters"));
    }
    if let Some(stripped) = name.strip_prefix(MAP_PREFIX) {
        return Err(format!("{name:?}: name the map without the channel prefix, as \"{stripped}\""));
    }
    Ok(())
}

/// A map in a g-buffer, as a look names it.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct MapInfo {
    pub name: String,
    /// Whether it is a colour map (`map.<name>.R/G/B`) rather than a scalar one (`map.<name>`).
    pub color: bool,
}

impl std::fmt::Display for MapInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.color {
            write!(f, "{MAP_PREFIX}{}.R/G/B", self.name)
        } else {
            write!(f, "{MAP_PREFIX}{}", self.name)
        }
    }
}

/// What a map binding names: one channel used as a value (a scalar map, or one channel of a
/// colour map), or a whole colour map.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MapSource {
    /// The channel's key in [`GBuffer::maps`].
    Channel(String),
    /// The keys of the colour map's R, G and B channels.
    Color([String; 3]),
}

impl GBuffer {
    /// The number of pixels, `width * height`.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The maps, by name: colour maps for every complete `.R/.G/.B` trio, scalar maps for every
    /// other map channel.
    pub fn maps(&self) -> Vec<MapInfo> {
        let mut maps = Vec::new();
        for channel in self.maps.keys() {
            match self.color_map_of(channel) {
                Some(name) if channel.ends_with(".R") => maps.push(MapInfo { name: name.to_string(), color: true }),
                Some(_) => {}
                None => maps.push(MapInfo { name: channel.clone(), color: false }),
            }
        }
        maps.sort();
        maps
    }

    /// The colour map a channel belongs to, when it ends in `.R`, `.G` or `.B` and its two
    /// siblings are there too.
    fn color_map_of<'a>(&self, channel: &'a str) -> Option<&'a str> {
        let (name, suffix) = channel.rsplit_once('.')?;
        (COLOR_MAP_CHANNELS.contains(&suffix)
            && COLOR_MAP_CHANNELS.iter().all(|c| self.maps.contains_key(&format!("{name}.{c}"))))
        .then_some(name)
    }

    /// What a binding's map name refers to: a colour map by its name, or a single channel (a
    /// scalar map, or `name.R|G|B` of a colour map). `None` when the g-buffer has no such map.
    pub fn map_source(&self, name: &str) -> Option<MapSource> {
        let trio = COLOR_MAP_CHANNELS.map(|c| format!("{name}.{c}"));
        if trio.iter().all(|c| self.maps.contains_key(c)) {
            return Some(MapSource::Color(trio));
        }
        self.maps.contains_key(name).then(|| MapSource::Channel(name.to_string()))
    }

    /// The maps, listed for a message: "map.baseColor.R/G/B, map.rough", or "no maps".
    pub fn map_list(&self) -> String {
        let maps = self.maps();
        if maps.is_empty() {
            "no maps".to_string()
        } else {
            maps.iter().map(MapInfo::to_string).collect::<Vec<_>>().join(", ")
        }
    }

    /// A mask or map channel by its full channel name (`mask.stripes`, `map.baseColor.R`).
    pub fn layer_channel(&self, channel: &str) -> Option<&[f32]> {
        if let Some(name) = channel.strip_prefix(MASK_PREFIX) {
            return self.masks.get(name).map(Vec::as_slice);
        }
        channel.strip_prefix(MAP_PREFIX).and_then(|name| self.maps.get(name)).map(Vec::as_slice)
    }

    /// The values of a channel the stacks read: [`GBuffer::layer_channel`], or a blurred mask
    /// (`mask.stripes@blur2`, [`crate::material::mask::MaskAdjust::channel_key`]) made from it.
    pub fn stack_channel(&self, channel: &str) -> Option<std::borrow::Cow<'_, [f32]>> {
        if let Some(values) = self.layer_channel(channel) {
            return Some(values.into());
        }
        let (source, sigma) = self.blurred_source(channel)?;
        Some(blur::blur(source, self.width, self.height, sigma).into())
    }

    /// Pixel `index` of [`GBuffer::stack_channel`], without making the whole channel.
    pub fn stack_channel_at(&self, channel: &str, index: usize) -> Option<f32> {
        if let Some(values) = self.layer_channel(channel) {
            return Some(values[index]);
        }
        let (source, sigma) = self.blurred_source(channel)?;
        Some(blur::blur_at(source, self.width, self.height, sigma, index))
    }

    /// The mask a blurred mask's channel is made from, and the blur's σ.
    fn blurred_source(&self, channel: &str) -> Option<(&[f32], f32)> {
        let key = channel.strip_prefix(MASK_PREFIX)?;
        let (name, sigma) = crate::material::mask::parse_blurred(key)?;
        Some((self.masks.get(name)?, sigma))
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_factor_divides_both_sides_and_is_bounded() {
        assert_eq!(super::check_supersample(2, 8, 6), Ok(()));
        assert!(super::check_supersample(2, 8, 5).unwrap_err().contains("8x5"));
        assert!(super::check_supersample(9, 9, 9).unwrap_err().contains("1 to 8"));
        assert!(super::check_supersample(0, 8, 8).is_err());
    }
}
