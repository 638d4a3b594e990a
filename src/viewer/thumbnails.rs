//! Preset thumbnails for the library browser: each preset rendered small on the built-in ball,
//! lit as the contact sheet is, and kept on disk so that the browser fills at once next time.
//!
//! A thumbnail is named by a hash of everything that makes its pixels: the preset's parameters,
//! the size, the sample count and a version that changes with the renderer. An edited preset
//! gets a new picture; a stale one is simply never asked for again.

use crate::atomic_file;
use crate::environment::Environment;
use crate::gbuffer::GBuffer;
use crate::gpu::Context;
use crate::material::stack::PackedStacks;
use crate::material::{Look, Params};
use crate::render::batch::preset_on_ball;
use crate::render::scene::covered_object_ids;
use crate::render::settings::{Overrides, Settings};
use crate::render::{progressive, Renderer};
use crate::Result;
use image::RgbaImage;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Thumbnail size in pixels, and samples per pixel.
pub const SIZE: u32 = 96;
pub const SPP: u32 = 32;
/// Bump when the renderer's output changes, so old pictures are not reused.
const VERSION: u32 = 1;

/// The folder thumbnails are kept in: `$XDG_CACHE_HOME/lookdev/thumbnails`, or
/// `~/.cache/lookdev/thumbnails`. `None` when neither variable is set.
pub fn cache_dir() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").filter(|v| !v.is_empty()).map(|home| Path::new(&home).join(".cache")))?;
    Some(base.join("lookdev").join("thumbnails"))
}

/// The cache file name of a preset's thumbnail.
pub fn file_name(params: &Params) -> String {
    // FNV-1a: stable across builds and platforms, unlike std's hasher.
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for &b in bytes {
            hash = (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    feed(&VERSION.to_le_bytes());
    feed(&SIZE.to_le_bytes());
    feed(&SPP.to_le_bytes());
    feed(bytemuck::cast_slice(&params.to_gpu()));
    format!("{hash:016x}.png")
}

/// Renders thumbnails and keeps them on disk.
pub struct Thumbnails {
    ctx: Context,
    dir: Option<PathBuf>,
    gbuffer: GBuffer,
    settings: Settings,
    renderer: Option<Renderer>,
    /// Pictures already made or read this session.
    memory: HashMap<String, RgbaImage>,
}

impl Thumbnails {
    /// Thumbnails kept in `dir` (none kept when `None`).
    pub fn new(ctx: &Context, dir: Option<PathBuf>) -> Result<Thumbnails> {
        // The default look's light, as on the contact sheet.
        let mut settings = Settings::resolve(&Look::builtin_default(), &Overrides::default())?;
        settings.spp = SPP;
        Ok(Thumbnails {
            ctx: ctx.clone(),
            dir,
            gbuffer: GBuffer::shaderball(SIZE, SIZE),
            settings,
            renderer: None,
            memory: HashMap::new(),
        })
    }

    /// The thumbnail of a preset: from memory, from disk, or, when `may_render` is true, rendered
    /// now (and `may_render` set to false, so a frame renders at most one). `None` when it
    /// would have to be rendered and may not be yet.
    pub fn get(&mut self, params: &Params, may_render: &mut bool) -> Result<Option<&RgbaImage>> {
        let name = file_name(params);
        if !self.memory.contains_key(&name) {
            let image = match self.read(&name) {
                Some(image) => image,
                None if *may_render => {
                    *may_render = false;
                    let image = self.render(params)?;
                    self.write(&name, &image);
                    image
                }
                None => return Ok(None),
            };
            self.memory.insert(name.clone(), image);
        }
        Ok(self.memory.get(&name))
    }

    fn read(&self, name: &str) -> Option<RgbaImage> {
        let image = image::open(self.dir.as_ref()?.join(name)).ok()?.into_rgba8();
        // A damaged or foreign file is rendered again, not shown.
        (image.dimensions() == (SIZE, SIZE)).then_some(image)
    }

    /// Keeps a picture on disk. A cache that cannot be written only costs a render next time,
    /// so a failure is a warning, once.
    fn write(&mut self, name: &str, image: &RgbaImage) {
        let Some(dir) = &self.dir else { return };
        let mut bytes = std::io::Cursor::new(Vec::new());
        let written = std::fs::create_dir_all(dir)
            .map_err(|e| e.to_string())
            .and_then(|_| image.write_to(&mut bytes, image::ImageFormat::Png).map_err(|e| e.to_string()))
            .and_then(|_| atomic_file::write(&dir.join(name), bytes.get_ref()).map_err(|e| e.to_string()));
        if let Err(problem) = written {
            crate::warn(format!("{}: thumbnails are not kept ({problem})", dir.display()));
            self.dir = None;
        }
    }

    fn render(&mut self, params: &Params) -> Result<RgbaImage> {
        let renderer = match &mut self.renderer {
            Some(renderer) => renderer,
            None => self.renderer.insert(Renderer::new(&self.ctx, &self.gbuffer, &Environment::studio())?),
        };
        let look = preset_on_ball(params);
        let stacks = PackedStacks::pack(
            &look,
            covered_object_ids(&self.gbuffer),
            &self.gbuffer,
            Path::new("built-in shader ball"),
        )?;
        renderer.set_stacks(&stacks)?;
        renderer.set_lighting(self.settings.lighting);
        renderer.set_seed(self.settings.seed);
        progressive::accumulate(renderer, self.settings.spp, |_| {})?;
        let pixels = renderer.read_display(self.settings.exposure, self.settings.tonemap)?;
        Ok(RgbaImage::from_raw(SIZE, SIZE, pixels).expect("the display image is SIZE×SIZE RGBA8"))
    }
}
