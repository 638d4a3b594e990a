//! Thumbnails for the browsers, kept on disk so that a browser fills at once next time: each
//! preset rendered small on the built-in ball, lit as the contact sheet is; and each
//! environment as its lat-long beside a chrome and a grey ball lit by it.
//!
//! A thumbnail is named by a hash of everything that makes its pixels: the preset's parameters
//! or the environment file's content, the light, the size, the sample count and a version that
//! changes with the renderer. An edited preset or map gets a new picture; a stale one is simply
//! never asked for again.

use crate::atomic_file;
use crate::environment::{Builtin, Environment, EnvironmentRef, LoadOptions};
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

/// An environment thumbnail's size: the lat-long, two [`SIZE`]s wide, then the two balls.
pub const ENVIRONMENT_SIZE: (u32, u32) = (4 * SIZE, SIZE);

/// The balls an environment thumbnail shows it on: a mirror-like chrome, and an 18% grey that
/// is purely diffuse.
fn chrome() -> Params {
    Params { base_color: [0.9; 3], metallic: 1.0, roughness: 0.0, ..Params::default() }
}
fn grey() -> Params {
    Params { base_color: [0.18; 3], specular: 0.0, roughness: 1.0, ..Params::default() }
}

/// A cache file name: the FNV-1a hash of the version, the size, the sample count and `parts`.
fn hashed_name(parts: &[&[u8]]) -> String {
    let bytes: Vec<u8> = [&VERSION.to_le_bytes()[..], &SIZE.to_le_bytes(), &SPP.to_le_bytes()]
        .into_iter()
        .chain(parts.iter().copied())
        .flatten()
        .copied()
        .collect();
    format!("{:016x}.png", crate::environment::content_hash(&bytes))
}

/// The cache file name of a preset's thumbnail; the default environment lights it.
pub fn file_name(params: &Params) -> String {
    let light = Builtin::default_one().content_hash().to_le_bytes();
    hashed_name(&[&light, bytemuck::cast_slice(&params.to_gpu())])
}

/// The cache file name of the thumbnail of an environment whose file hashes to `content_hash`.
pub fn environment_file_name(content_hash: u64) -> String {
    hashed_name(&[b"environment", &content_hash.to_le_bytes()])
}

/// Renders thumbnails and keeps them on disk.
pub struct Thumbnails {
    ctx: Context,
    dir: Option<PathBuf>,
    gbuffer: GBuffer,
    settings: Settings,
    renderer: Option<Renderer>,
    /// The content hash of the environment the renderer holds.
    lit_by: u64,
    /// Pictures already made or read this session.
    memory: HashMap<String, RgbaImage>,
    /// Environment files' content hashes, read once a session.
    file_hashes: HashMap<EnvironmentRef, std::result::Result<u64, String>>,
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
            lit_by: 0,
            memory: HashMap::new(),
            file_hashes: HashMap::new(),
        })
    }

    /// The thumbnail of a preset: from memory, from disk, or, when `may_render` is true, rendered
    /// now (and `may_render` set to false, so a frame renders at most one). `None` when it
    /// would have to be rendered and may not be yet.
    pub fn get(&mut self, params: &Params, may_render: &mut bool) -> Result<Option<&RgbaImage>> {
        let params = *params;
        self.cached(file_name(&params), (SIZE, SIZE), may_render, |this| {
            let default = Builtin::default_one();
            this.ball(&params, default.content_hash(), || Ok(default.load()))
        })
    }

    /// The thumbnail of an environment, as [`Thumbnails::get`] gives a preset's: its lat-long,
    /// a chrome ball and a grey ball, side by side. A file is read to hash it once a session,
    /// which takes the frame's turn as a render does; one that cannot be read is an error.
    pub fn environment(&mut self, reference: &EnvironmentRef, may_render: &mut bool) -> Result<Option<&RgbaImage>> {
        let hash = match reference {
            EnvironmentRef::Builtin(name) => Builtin::find(name).map_err(crate::Error::input)?.content_hash(),
            EnvironmentRef::File(path) => match self.file_hashes.get(reference) {
                Some(hash) => hash.clone().map_err(crate::Error::input)?,
                None if *may_render => {
                    *may_render = false;
                    let hash = crate::input::read(path, crate::input::Kind::Environment)
                        .map(|bytes| crate::environment::content_hash(&bytes))
                        .map_err(|e| e.message);
                    self.file_hashes.insert(reference.clone(), hash.clone());
                    hash.map_err(crate::Error::input)?;
                    return Ok(None);
                }
                None => return Ok(None),
            },
        };
        self.cached(environment_file_name(hash), ENVIRONMENT_SIZE, may_render, |this| {
            let environment = reference.load(&LoadOptions::default())?;
            let lat_long = lat_long(&environment, 2 * SIZE, SIZE, &this.settings);
            let mut image = RgbaImage::new(ENVIRONMENT_SIZE.0, ENVIRONMENT_SIZE.1);
            image::imageops::replace(&mut image, &lat_long, 0, 0);
            let mut environment = Some(environment);
            let mut take = || Ok(environment.take().expect("loaded once"));
            let chrome = this.ball(&chrome(), hash, &mut take)?;
            image::imageops::replace(&mut image, &chrome, 2 * SIZE as i64, 0);
            let grey = this.ball(&grey(), hash, &mut take)?;
            image::imageops::replace(&mut image, &grey, 3 * SIZE as i64, 0);
            Ok(image)
        })
    }

    /// A picture from memory, from disk, or made by `render` when `may_render` allows.
    fn cached(
        &mut self,
        name: String,
        size: (u32, u32),
        may_render: &mut bool,
        render: impl FnOnce(&mut Thumbnails) -> Result<RgbaImage>,
    ) -> Result<Option<&RgbaImage>> {
        if !self.memory.contains_key(&name) {
            let image = match self.read(&name, size) {
                Some(image) => image,
                None if *may_render => {
                    *may_render = false;
                    let image = render(self)?;
                    self.write(&name, &image);
                    image
                }
                None => return Ok(None),
            };
            self.memory.insert(name.clone(), image);
        }
        Ok(self.memory.get(&name))
    }

    fn read(&self, name: &str, size: (u32, u32)) -> Option<RgbaImage> {
        let image = image::open(self.dir.as_ref()?.join(name)).ok()?.into_rgba8();
        // A damaged or foreign file is rendered again, not shown.
        (image.dimensions() == size).then_some(image)
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

    /// `params` on the ball, lit by the environment hashing to `light`; `environment` gives it
    /// when the renderer does not hold it already.
    fn ball(
        &mut self,
        params: &Params,
        light: u64,
        environment: impl FnOnce() -> Result<Environment>,
    ) -> Result<RgbaImage> {
        let renderer = match &mut self.renderer {
            Some(renderer) => {
                if self.lit_by != light {
                    renderer.set_environment(&environment()?)?;
                }
                renderer
            }
            None => self.renderer.insert(Renderer::new(&self.ctx, &self.gbuffer, &environment()?)?),
        };
        self.lit_by = light;
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

/// The environment shrunk to `width`×`height` (each pixel the mean of the texels it covers),
/// tone-mapped for display as the renders are.
fn lat_long(environment: &Environment, width: u32, height: u32, settings: &Settings) -> RgbaImage {
    let (w, h) = (environment.width as u64, environment.height as u64);
    let span = |i: u32, n: u32, of: u64| {
        let start = i as u64 * of / n as u64;
        start..(((i as u64 + 1) * of / n as u64).max(start + 1)).min(of)
    };
    RgbaImage::from_fn(width, height, |x, y| {
        let (xs, ys) = (span(x, width, w), span(y, height, h));
        let mut sum = glam::Vec3::ZERO;
        for ty in ys.clone() {
            for tx in xs.clone() {
                sum += glam::Vec3::from(environment.texel(tx as u32, ty as u32));
            }
        }
        let mean = sum / (xs.count() * ys.count()).max(1) as f32;
        let [r, g, b] = crate::shading::tonemap::display_pixel(
            mean * settings.lighting.intensity,
            settings.exposure,
            settings.tonemap,
        );
        image::Rgba([r, g, b, 255])
    })
}
