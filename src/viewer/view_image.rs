//! The view on screen and its CPU copy: the current view's linear values and display pixels,
//! refreshed as samples land (at 1, 2, 4, … samples, at the target, and at least every
//! [`REFRESH`] while accumulating, but never for more than a tenth of the time) and at once
//! after an edit, never every frame. The copy feeds
//! the view's texture (the beauty is shown straight from the renderer's display image
//! instead), the clipping overlay, the histogram, the value under the cursor and `probe`.

use super::session::Session;
use super::views::{self, Histogram, View, ViewChoice};
use crate::render::aov::{self, Aov};
use crate::{Error, Result};
use std::path::Path;
use std::time::{Duration, Instant};

/// The longest the copy lags the accumulation.
const REFRESH: Duration = Duration::from_millis(300);

/// The current view's values, as last read.
pub struct ViewImage {
    pub view: View,
    /// 1 for a scalar AOV, 3 for a colour or vector.
    pub channels: usize,
    pub width: u32,
    /// Linear values per pixel (a scalar in channel 0).
    pub linear: Vec<[f32; 3]>,
    /// Display-referred sRGB bytes per pixel, as the view shows them. Empty for the beauty
    /// while the clipping overlay is off: the renderer's display image shows it, and the value
    /// under the cursor is encoded alone.
    pub display: Vec<[u8; 3]>,
    /// What the display encodes, where it is not `linear` (the beauty's surface colour, with
    /// the background off).
    shown: Option<Vec<[f32; 3]>>,
    /// How, with the settings of the read.
    encoding: views::Encoding,
    exposure: f32,
    tonemap: crate::shading::tonemap::Tonemap,
    pub histogram: Option<Histogram>,
    /// The samples and the document's edition it was read at.
    pub samples: u32,
    edition: Edition,
}

impl ViewImage {
    /// "view NAME pixel X,Y linear V[,V,V] display R,G,B": what `probe` prints and the status
    /// bar shows under the cursor.
    pub fn describe(&self, x: u32, y: u32) -> Option<String> {
        let p = (y as usize).checked_mul(self.width as usize)? + x as usize;
        let v = self.linear.get(p)?;
        let d = match self.display.get(p) {
            Some(d) => *d,
            None => {
                let shown = self.shown.as_ref().unwrap_or(&self.linear).get(p)?;
                views::encode(self.encoding, *shown, self.exposure, self.tonemap)
            }
        };
        let linear = match self.channels {
            1 => format!("{:.6}", v[0]),
            _ => format!("{:.6},{:.6},{:.6}", v[0], v[1], v[2]),
        };
        Some(format!("view {} pixel {x},{y} linear {linear} display {},{},{}", self.view.name(), d[0], d[1], d[2]))
    }
}

/// The view being shown, its copy, and its textures.
pub struct Views {
    current: View,
    /// The view `E` returns to from false colour.
    before_false_colour: View,
    /// The clipping overlay is on.
    pub clipping: bool,
    image: Option<ViewImage>,
    texture: Option<egui::TextureHandle>,
    overlay: Option<egui::TextureHandle>,
    /// The textures show this copy (its view, samples and edition), and whether the overlay
    /// was made (only while it is on).
    overlay_of: Option<(View, u32, Edition, bool)>,
    refreshed_at: Instant,
    /// How long the last refresh of the copy took.
    cost: Duration,
}

impl Default for Views {
    fn default() -> Views {
        Views {
            current: View::Beauty,
            before_false_colour: View::Beauty,
            clipping: false,
            image: None,
            texture: None,
            overlay: None,
            overlay_of: None,
            refreshed_at: Instant::now(),
            cost: Duration::ZERO,
        }
    }
}

impl Views {
    pub fn current(&self) -> &View {
        &self.current
    }

    /// Every view of the session, in `C`'s order.
    pub fn list(session: &Session) -> Vec<View> {
        views::list(&session.gbuffer, session.document.look())
    }

    /// Changes the view, and what A's renderer accumulates for it (at once, so that a script's
    /// next `wait-spp` waits for the view's own samples). Returns the status message.
    pub fn choose(&mut self, session: &mut Session, choice: ViewChoice) -> Result<String> {
        let list = Views::list(session);
        let at = list.iter().position(|v| *v == self.current).unwrap_or(0);
        let view = match choice {
            ViewChoice::Named(name) => views::parse(&name, &list).map_err(Error::input)?,
            ViewChoice::Next => list[(at + 1) % list.len()].clone(),
            ViewChoice::Previous => list[(at + list.len() - 1) % list.len()].clone(),
            ViewChoice::Beauty => View::Beauty,
            ViewChoice::FalseColour if self.current == View::FalseColour => self.before_false_colour.clone(),
            ViewChoice::FalseColour => View::FalseColour,
        };
        if view == View::FalseColour && self.current != View::FalseColour {
            self.before_false_colour = self.current.clone();
        }
        self.current = view;
        self.sync_accumulate(session)?;
        Ok(format!("view {}", self.current.name()))
    }

    /// Has A's renderer accumulate what the current view needs, and no more: the extra
    /// accumulation costs speed, so it goes when the view no longer needs it.
    fn sync_accumulate(&mut self, session: &mut Session) -> Result<()> {
        session.set_accumulate(self.current.accumulate())
    }

    /// Turns the clipping overlay on or off (`None`: toggles it).
    pub fn set_clipping(&mut self, on: Option<bool>) -> String {
        self.clipping = on.unwrap_or(!self.clipping);
        format!("clipping overlay {}", if self.clipping { "on" } else { "off" })
    }

    /// Brings the renderer's accumulation, the copy and the textures up to date; called once a
    /// frame, before the interface. Reads back only when the throttle allows.
    pub fn update(&mut self, session: &mut Session, egui: &egui::Context) -> Result<()> {
        // A layer view whose layer went (removed, or its preset changed) falls back to the beauty.
        if matches!(self.current, View::Layer(_)) && !Views::list(session).contains(&self.current) {
            self.current = View::Beauty;
        }
        self.sync_accumulate(session)?;
        if self.due(session) {
            self.refresh(session)?;
        }
        self.upload(session, egui);
        Ok(())
    }

    /// Whether the copy should be read again now.
    fn due(&self, session: &Session) -> bool {
        let samples = session.a_samples();
        let Some(image) = &self.image else { return self.readable(session) };
        let overlay_unmade = self.clipping && image.display.is_empty();
        if image.view != self.current || image.edition != edition(session) || overlay_unmade {
            return self.readable(session);
        }
        if !self.current.follows_samples() || samples == image.samples || samples == 0 {
            return false;
        }
        if samples >= session.target() {
            return true;
        }
        // Reading the copy costs a CPU driver tens of milliseconds at 1024²: while the image
        // converges, it takes at most a tenth of the time.
        let since = self.refreshed_at.elapsed();
        since >= self.cost * 9
            && (super::progressive::read_again(image.samples, samples, session.target()) || since >= REFRESH)
    }

    /// Whether the view's values can be read: a view that follows samples needs a full pass.
    fn readable(&self, session: &Session) -> bool {
        !self.current.follows_samples() || session.a_samples() > 0
    }

    /// Reads the current view's values and makes its display pixels and histogram.
    fn refresh(&mut self, session: &mut Session) -> Result<()> {
        let started = Instant::now();
        let view = self.current.clone();
        let settings = session.document.settings().clone();
        let Values { channels, linear, shown } = match &view {
            View::Beauty | View::FalseColour => {
                let radiance = session.radiance()?;
                let linear = radiance.iter().map(|r| [r[0], r[1], r[2]]).collect();
                // With the background off the radiance is premultiplied; the display shows the
                // surface's own colour, as the renderer's display image does.
                let shown = radiance
                    .iter()
                    .map(|r| {
                        if r[3] > 0.0 && r[3] < 1.0 {
                            [r[0] / r[3], r[1] / r[3], r[2] / r[3]]
                        } else {
                            [r[0], r[1], r[2]]
                        }
                    })
                    .collect();
                Values { channels: 3, linear, shown: Some(shown) }
            }
            View::Aov(aov) => layer_values(session.aov_layers(&[*aov])?.into_iter().next())?,
            View::Mask(name) => find_layer(session.aov_layers(&[Aov::Masks])?, &aov::mask_layer(name))?,
            View::Map(name) => find_layer(session.aov_layers(&[Aov::Maps])?, &aov::map_layer(name))?,
            View::Layer(name) => find_layer(session.aov_layers(&[Aov::Layers])?, name)?,
        };
        let encoding = view.encoding(channels);
        let (exposure, tonemap) = (settings.exposure, settings.tonemap);
        // The beauty needs display pixels only for the overlay: encoding a large image costs.
        let display = if view != View::Beauty || self.clipping {
            shown.as_ref().unwrap_or(&linear).iter().map(|v| views::encode(encoding, *v, exposure, tonemap)).collect()
        } else {
            Vec::new()
        };
        // Radiance with the background shown counts every pixel; everything else the covered ones.
        let everything = view.is_radiance() && settings.lighting.background;
        let coverage = &session.gbuffer.coverage;
        let histogram = views::histogram(encoding, &linear, |p| everything || coverage[p] > 0.0, exposure);
        self.image = Some(ViewImage {
            view,
            channels,
            width: session.width(),
            linear,
            display,
            shown,
            encoding,
            exposure,
            tonemap,
            histogram,
            samples: session.a_samples(),
            edition: edition(session),
        });
        self.refreshed_at = Instant::now();
        self.cost = started.elapsed();
        Ok(())
    }

    /// Makes the view's texture and the overlay's from the copy, when they changed.
    fn upload(&mut self, session: &Session, egui: &egui::Context) {
        let Some(image) = &self.image else { return };
        let size = [session.width() as usize, session.height() as usize];
        let key = (image.view.clone(), image.samples, image.edition.clone(), self.clipping);
        if self.overlay_of.as_ref() == Some(&key) {
            return;
        }
        self.overlay_of = Some(key);
        let options =
            egui::TextureOptions { magnification: egui::TextureFilter::Nearest, ..egui::TextureOptions::LINEAR };
        if image.view != View::Beauty {
            let pixels: Vec<egui::Color32> =
                image.display.iter().map(|d| egui::Color32::from_rgb(d[0], d[1], d[2])).collect();
            let colour = egui::ColorImage::new(size, pixels);
            match &mut self.texture {
                Some(texture) => texture.set(colour, options),
                None => self.texture = Some(egui.load_texture("view", colour, options)),
            }
        }
        if !self.clipping {
            return; // made when the overlay is turned on
        }
        // A radiance view is marked everywhere; a value view only where it has values.
        let coverage = &session.gbuffer.coverage;
        let everywhere = image.view.is_radiance();
        let marks: Vec<egui::Color32> = image
            .display
            .iter()
            .zip(coverage)
            .map(|(d, &a)| match views::clip_mark(*d).filter(|_| everywhere || a > 0.0) {
                Some(m) => egui::Color32::from_rgb(m[0], m[1], m[2]),
                None => egui::Color32::TRANSPARENT,
            })
            .collect();
        let marks = egui::ColorImage::new(size, marks);
        match &mut self.overlay {
            Some(overlay) => overlay.set(marks, options),
            None => self.overlay = Some(egui.load_texture("clipping", marks, options)),
        }
    }

    /// The current view's copy, when it has been read for the current view.
    pub fn image(&self) -> Option<&ViewImage> {
        self.image.as_ref().filter(|i| i.view == self.current)
    }

    /// The texture to show instead of the beauty: `None` for the beauty, or while a view's
    /// first values are being rendered.
    pub fn texture(&self) -> Option<egui::TextureId> {
        let shown = self.image().is_some_and(|i| i.view != View::Beauty);
        self.texture.as_ref().filter(|_| shown).map(egui::TextureHandle::id)
    }

    /// The clipping overlay's texture, while it is on and made for the current view.
    pub fn overlay(&self) -> Option<egui::TextureId> {
        let current = self.overlay_of.as_ref().is_some_and(|(view, .., made)| *view == self.current && *made);
        self.overlay.as_ref().filter(|_| self.clipping && current).map(egui::TextureHandle::id)
    }

    /// Whether the view waits for its first samples (after a switch that restarted them).
    pub fn waiting(&self) -> bool {
        self.current != View::Beauty && self.image().is_none()
    }

    /// `probe X Y`: the current view's values at a pixel, read now if the copy is behind.
    pub fn probe(&mut self, session: &mut Session, x: u32, y: u32) -> Result<String> {
        if x >= session.width() || y >= session.height() {
            return Err(Error::input(format!(
                "pixel {x},{y} is outside the {}x{} image",
                session.width(),
                session.height()
            )));
        }
        self.sync_accumulate(session)?;
        let stale = self.image().is_none_or(|i| {
            i.edition != edition(session) || (self.current.follows_samples() && i.samples != session.a_samples())
        });
        if stale {
            if !self.readable(session) {
                return Err(Error::input(format!(
                    "view {} has no samples yet: wait for them first (`wait-spp 1`)",
                    self.current.name()
                )));
            }
            self.refresh(session)?;
        }
        let image = self.image().expect("just read");
        Ok(image.describe(x, y).expect("inside the image"))
    }
}

/// What the document's content is known by: its revision, which changes with every change,
/// and its file, since another look opened starts at revision 0 again.
type Edition = (u64, Option<std::path::PathBuf>);

fn edition(session: &Session) -> Edition {
    (session.document.revision(), session.document.path().map(Path::to_path_buf))
}

/// A view's values as read: linear, and where the display shows other values (the beauty's
/// surface colour, with the background off), those.
struct Values {
    channels: usize,
    linear: Vec<[f32; 3]>,
    shown: Option<Vec<[f32; 3]>>,
}

/// The values of an AOV layer of one or three channels.
fn layer_values(layer: Option<aov::Layer>) -> Result<Values> {
    let layer = layer.ok_or_else(|| Error::gpu("the view's AOV has no layer"))?;
    let channel = |k: usize| &layer.channels[k.min(layer.channels.len() - 1)].1;
    let channels = if layer.channels.len() >= 3 { 3 } else { 1 };
    let values = (0..channel(0).len()).map(|p| [channel(0)[p], channel(1)[p], channel(2)[p]]).collect();
    Ok(Values { channels, linear: values, shown: None })
}

/// The layer named `name` among an AOV's layers.
fn find_layer(layers: Vec<aov::Layer>, name: &str) -> Result<Values> {
    layer_values(layers.into_iter().find(|l| l.name == name))
}
