//! Edits: every change the viewer can make to a document, checked and applied to a copy of its
//! state, so that an edit that fails has changed nothing.

use std::fmt;

use crate::environment::backdrop::{self, Backdrop};
use crate::environment::EnvironmentRef;
use crate::material::look::{EnvironmentSettings, Layer, Look, ObjectStack, RenderSettings};
use crate::material::mask::MaskAdjust;
use crate::material::params::{Param, Params, Value};
use crate::render::settings::{Settings, DEFAULT_MIN_SPP, DEFAULT_SPP};
use crate::render::Lighting;
use crate::shading::model::Model;
use crate::shading::tonemap::{Tonemap, MAX_EXPOSURE};

/// The longest layer name, in characters.
pub const MAX_LAYER_NAME: usize = 80;

/// Which layer stack an edit is aimed at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ObjectRef {
    /// The stack of this object id. Until the object has a stack of its own, it shows the
    /// default stack, and the first edit aimed at it gives it a copy (see [`Edit`]).
    Id(u32),
    /// The default stack, used by every object without a stack of its own.
    Default,
}

impl ObjectRef {
    /// The stack's `id` in the look: `None` for the default stack.
    pub fn id(self) -> Option<u32> {
        match self {
            ObjectRef::Id(id) => Some(id),
            ObjectRef::Default => None,
        }
    }
}

impl fmt::Display for ObjectRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ObjectRef::Id(id) => write!(f, "object {id}"),
            ObjectRef::Default => f.write_str("the default stack"),
        }
    }
}

/// One change to a document. Layers count from 0 at the bottom of their stack.
///
/// A stack edit aimed at an object without a stack of its own first gives it one, a copy of
/// the default stack (or one default-material layer when there is no default stack), and one
/// aimed at [`ObjectRef::Default`] in a look without a default stack first adds one of a single
/// default-material layer. That creation is part of the same undo step, and happens only when
/// the edit succeeds and changes something.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Sets a parameter of a layer, checked as [`crate::material::params::check`] does, and marks
    /// it as overridden, so that saving writes it.
    SetParam {
        object: ObjectRef,
        layer: usize,
        param: Param,
        value: Value,
    },
    /// Puts a parameter back to the value of the layer's preset (the default for a layer without
    /// a preset); it is no longer an override.
    ResetParam {
        object: ObjectRef,
        layer: usize,
        param: Param,
    },
    /// Adds a layer of a preset on top of the stack: enabled, opacity 1, no mask, no overrides.
    /// The name (or path) resolves through the look's library: the look's folder, the user
    /// library, then the built-ins.
    AddLayer {
        object: ObjectRef,
        preset: String,
    },
    /// Adds a layer of a preset as [`Edit::AddLayer`] does, at index `at`: the layers from
    /// `at` up move one up, and `at` = the number of layers puts it on top. A preset dropped
    /// between two layers of the stack panel is this.
    InsertLayer {
        object: ObjectRef,
        preset: String,
        at: usize,
    },
    /// Removes a layer. A stack keeps at least one layer, so removing the last is an error.
    RemoveLayer {
        object: ObjectRef,
        layer: usize,
    },
    /// Moves a layer so that it ends up at index `to`.
    MoveLayer {
        object: ObjectRef,
        from: usize,
        to: usize,
    },
    /// Copies a layer; the copy goes just above the original.
    DuplicateLayer {
        object: ObjectRef,
        layer: usize,
    },
    /// Shows or hides a layer without removing it (`enabled` in the look format).
    SetEnabled {
        object: ObjectRef,
        layer: usize,
        enabled: bool,
    },
    /// Binds a parameter of a layer to a g-buffer map (`name`, or `name.R|G|B` for one
    /// channel), or unbinds it with `None`; the value stays, as the factor the map multiplies.
    /// A name must not be empty. Whether the g-buffer has the map is the viewer's to check.
    SetMap {
        object: ObjectRef,
        layer: usize,
        param: Param,
        map: Option<String>,
    },
    /// The g-buffer mask that weights a layer; `None` is 1 everywhere. A name must not be empty.
    SetMask {
        object: ObjectRef,
        layer: usize,
        mask: Option<String>,
    },
    SetInvert {
        object: ObjectRef,
        layer: usize,
        invert: bool,
    },
    /// The blur and levels of a layer's mask, checked as the look format checks them.
    SetMaskAdjust {
        object: ObjectRef,
        layer: usize,
        adjust: MaskAdjust,
    },
    /// Names a layer (`None`: back to its preset's name). A name is trimmed and must not be
    /// empty or longer than [`MAX_LAYER_NAME`] characters.
    RenameLayer {
        object: ObjectRef,
        layer: usize,
        name: Option<String>,
    },
    /// In [0, 1].
    SetOpacity {
        object: ObjectRef,
        layer: usize,
        opacity: f32,
    },
    /// Makes an object catch shadows, or not (`shadow_catcher` in the look format).
    SetShadowCatcher {
        object: ObjectRef,
        catcher: bool,
    },
    /// Gives an object a stack of its own, a copy of the default stack (or one default-material
    /// layer). Nothing happens when it already has one.
    CreateStack {
        id: u32,
    },
    /// Environment rotation in degrees about +Y; any finite number.
    SetRotation(f32),
    /// Environment radiance scale; finite and ≥ 0.
    SetIntensity(f32),
    /// Whether background pixels show a background ([`Edit::SetBackdrop`] says which).
    SetBackground(bool),
    /// What the background is; shows it, as `SetBackground(true)` does.
    SetBackdrop(Backdrop),
    /// The environment: a built-in or an image file; `None` is the default built-in. The file is
    /// not read here: loading it is the viewer's job.
    SetEnvironment(Option<EnvironmentRef>),
    /// Exposure in stops, within ±[`MAX_EXPOSURE`].
    SetExposure(f32),
    SetTonemap(Tonemap),
    /// The samples per pixel accumulation stops at; at least 1.
    SetTargetSpp(u32),
    SetSeed(u32),
    /// The BRDF model (the look's `[model]` table).
    SetModel(Model),
    /// Replaces the look and the render settings at once, as restoring a snapshot does: one
    /// undo step, so that undo brings back exactly the state before. The look keeps the
    /// document's file, and its `[environment]` and `[render]` tables follow the settings.
    Restore {
        look: Box<Look>,
        settings: Box<Settings>,
    },
}

/// What makes two edits parts of one gesture, such as a slider drag: the same kind of edit on the
/// same target. Only continuous controls have one; toggles and structural edits never merge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MergeKey {
    Param(ObjectRef, usize, Param),
    Opacity(ObjectRef, usize),
    Mask(ObjectRef, usize),
    MaskAdjust(ObjectRef, usize),
    Rotation,
    Intensity,
    /// A background colour or blur being dragged.
    Backdrop,
    Exposure,
    TargetSpp,
    Seed,
}

impl Edit {
    /// The key under which [`Document::apply_merging`](super::Document::apply_merging) folds
    /// this edit into the previous one, if it is a continuous control.
    pub fn merge_key(&self) -> Option<MergeKey> {
        match *self {
            Edit::SetParam { object, layer, param, .. } => Some(MergeKey::Param(object, layer, param)),
            Edit::SetOpacity { object, layer, .. } => Some(MergeKey::Opacity(object, layer)),
            Edit::SetMask { object, layer, .. } => Some(MergeKey::Mask(object, layer)),
            Edit::SetMaskAdjust { object, layer, .. } => Some(MergeKey::MaskAdjust(object, layer)),
            Edit::SetRotation(_) => Some(MergeKey::Rotation),
            Edit::SetIntensity(_) => Some(MergeKey::Intensity),
            Edit::SetBackdrop(Backdrop::Colour(_) | Backdrop::Blurred(_)) => Some(MergeKey::Backdrop),
            Edit::SetExposure(_) => Some(MergeKey::Exposure),
            Edit::SetTargetSpp(_) => Some(MergeKey::TargetSpp),
            Edit::SetSeed(_) => Some(MergeKey::Seed),
            _ => None,
        }
    }
}

/// Everything an undo step restores: the look (its stacks, and its `[environment]` and `[render]`
/// tables, which mirror the settings) and the render settings.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct State {
    pub look: Look,
    pub settings: Settings,
}

/// Finds a preset's parameters by the reference a layer gives (a name or a path).
pub(super) type Presets<'a> = &'a dyn Fn(&str) -> Result<Params, String>;

impl State {
    /// The state with `edit` applied, or why it cannot be; `self` is never changed. `saved` is
    /// the look as last loaded or saved, for [`State::mirror_settings`].
    pub fn applied(&self, edit: Edit, presets: Presets, saved: &Look) -> Result<State, String> {
        let mut next = self.clone();
        match edit {
            Edit::SetParam { object, layer, param, value } => next.edit_stack(object, |stack| {
                let layer = layer_mut(stack, object, layer)?;
                layer.params.set(param, value)?;
                if !layer.overrides.contains(&param) {
                    layer.overrides.push(param);
                    // Param's order is Param::ALL's, the order the look format writes overrides in.
                    layer.overrides.sort();
                }
                Ok(())
            })?,
            Edit::ResetParam { object, layer, param } => next.edit_stack(object, |stack| {
                let layer = layer_mut(stack, object, layer)?;
                // A parameter that is not overridden already has its preset's value.
                if layer.overrides.contains(&param) {
                    let preset = match &layer.preset {
                        Some(reference) => presets(reference)?,
                        None => Params::default(),
                    };
                    layer.params.set(param, preset.get(param))?;
                    layer.overrides.retain(|&p| p != param);
                }
                Ok(())
            })?,
            Edit::AddLayer { object, preset } => next.edit_stack(object, |stack| {
                let top = stack.layers.len();
                insert_layer(stack, object, preset, top, presets)
            })?,
            Edit::InsertLayer { object, preset, at } => {
                next.edit_stack(object, |stack| insert_layer(stack, object, preset, at, presets))?
            }
            Edit::RemoveLayer { object, layer } => next.edit_stack(object, |stack| {
                check_layer(object, layer, stack.layers.len())?;
                if stack.layers.len() == 1 {
                    return Err(format!("{object} has only this layer, and a stack keeps at least one"));
                }
                stack.layers.remove(layer);
                Ok(())
            })?,
            Edit::MoveLayer { object, from, to } => next.edit_stack(object, |stack| {
                check_layer(object, from, stack.layers.len())?;
                check_layer(object, to, stack.layers.len())?;
                let moved = stack.layers.remove(from);
                stack.layers.insert(to, moved);
                Ok(())
            })?,
            Edit::DuplicateLayer { object, layer } => next.edit_stack(object, |stack| {
                let copy =
                    Layer { id: crate::material::look::LayerId::new(), ..layer_mut(stack, object, layer)?.clone() };
                stack.layers.insert(layer + 1, copy);
                Ok(())
            })?,
            Edit::SetEnabled { object, layer, enabled } => next.edit_stack(object, |stack| {
                layer_mut(stack, object, layer)?.enabled = enabled;
                Ok(())
            })?,
            Edit::SetMap { object, layer, param, map } => next.edit_stack(object, |stack| {
                let layer = layer_mut(stack, object, layer)?;
                match map {
                    Some(map) => {
                        crate::gbuffer::check_map_name(&map).map_err(|problem| format!("{param}: {problem}"))?;
                        layer.maps.insert(param, map)
                    }
                    None => layer.maps.remove(&param),
                };
                Ok(())
            })?,
            Edit::SetMask { object, layer, mask } => next.edit_stack(object, |stack| {
                if mask.as_deref().is_some_and(|m| m.trim().is_empty()) {
                    return Err("a mask name must not be empty (no mask is 1 everywhere)".to_string());
                }
                layer_mut(stack, object, layer)?.mask = mask;
                Ok(())
            })?,
            Edit::SetInvert { object, layer, invert } => next.edit_stack(object, |stack| {
                layer_mut(stack, object, layer)?.invert = invert;
                Ok(())
            })?,
            Edit::SetMaskAdjust { object, layer, adjust } => next.edit_stack(object, |stack| {
                adjust.check()?;
                layer_mut(stack, object, layer)?.mask_adjust = adjust;
                Ok(())
            })?,
            Edit::RenameLayer { object, layer, name } => next.edit_stack(object, |stack| {
                let name = name.map(|n| n.trim().to_string());
                match &name {
                    Some(n) if n.is_empty() => return Err("a layer's name must not be empty".to_string()),
                    Some(n) if n.chars().count() > MAX_LAYER_NAME => {
                        return Err(format!("a layer's name is at most {MAX_LAYER_NAME} characters"))
                    }
                    _ => {}
                }
                layer_mut(stack, object, layer)?.name = name;
                Ok(())
            })?,
            Edit::SetOpacity { object, layer, opacity } => next.edit_stack(object, |stack| {
                if !(0.0..=1.0).contains(&opacity) {
                    return Err(format!("opacity = {opacity} is out of range [0, 1]"));
                }
                layer_mut(stack, object, layer)?.opacity = opacity;
                Ok(())
            })?,
            Edit::SetShadowCatcher { object, catcher } => next.edit_stack(object, |stack| {
                stack.shadow_catcher = catcher;
                Ok(())
            })?,
            Edit::CreateStack { id } => {
                stack_mut(&mut next.look, ObjectRef::Id(id));
            }
            Edit::SetRotation(degrees) => {
                if !degrees.is_finite() {
                    return Err(format!("rotation {degrees} must be a finite number of degrees"));
                }
                next.settings.lighting.rotation_degrees = degrees;
            }
            Edit::SetIntensity(intensity) => {
                crate::environment::check_intensity(intensity)?;
                next.settings.lighting.intensity = intensity;
            }
            Edit::SetBackground(background) => next.settings.lighting.background = background,
            Edit::SetBackdrop(backdrop) => {
                match &backdrop {
                    Backdrop::Environment => {}
                    Backdrop::Blurred(degrees) => backdrop::check_blur(*degrees)?,
                    Backdrop::Colour(rgb) => backdrop::check_colour(*rgb)?,
                    Backdrop::Other(other) => {
                        if other.file().is_some_and(|f| f.as_os_str().is_empty()) {
                            return Err("the background environment file must not be empty".to_string());
                        }
                    }
                }
                next.settings.backdrop = backdrop;
                next.settings.lighting.background = true;
            }
            Edit::SetEnvironment(file) => {
                if file.as_ref().and_then(EnvironmentRef::file).is_some_and(|f| f.as_os_str().is_empty()) {
                    return Err("the environment file must not be empty (none is the default environment)".to_string());
                }
                next.settings.environment = file;
            }
            Edit::SetExposure(stops) => {
                if !(stops.is_finite() && stops.abs() <= MAX_EXPOSURE) {
                    return Err(format!("exposure {stops} must be within ±{MAX_EXPOSURE} stops"));
                }
                next.settings.exposure = stops;
            }
            Edit::SetTonemap(tonemap) => next.settings.tonemap = tonemap,
            Edit::SetTargetSpp(spp) => {
                if spp == 0 {
                    return Err("the sample count must be at least 1".to_string());
                }
                next.settings.spp = spp;
            }
            Edit::SetSeed(seed) => next.settings.seed = seed,
            Edit::SetModel(model) => next.settings.model = model,
            Edit::Restore { look, settings } => {
                let file = next.look.file.take();
                next.look = *look;
                next.look.file = file;
                next.settings = *settings;
            }
        }
        next.mirror_settings(saved);
        Ok(next)
    }

    /// Runs a stack edit on the stack for `object`, creating that stack first when it is missing
    /// (see [`Edit`]). A stack created for an edit that then changes nothing is taken away again.
    fn edit_stack(
        &mut self,
        object: ObjectRef,
        edit: impl FnOnce(&mut ObjectStack) -> Result<(), String>,
    ) -> Result<(), String> {
        let created = !has_stack(&self.look, object);
        let stack = stack_mut(&mut self.look, object);
        let fresh = created.then(|| stack.clone());
        edit(stack)?;
        if fresh.is_some_and(|fresh| fresh == *stack) {
            // The created stack is the last one.
            self.look.objects.pop();
        }
        Ok(())
    }

    /// Writes the settings into the look's `[environment]` and `[render]` tables, so that a saved
    /// look reopens as it was. A value is written when the `saved` look (as last loaded or saved)
    /// wrote it, or when it differs from lookdev's default. So a look that left a table out keeps
    /// it out while its settings are at their defaults, and a setting dragged away and back
    /// leaves the look as it was.
    pub fn mirror_settings(&mut self, saved: &Look) {
        fn keep<T: PartialEq, U>(written: Option<U>, value: T, default: T) -> Option<T> {
            (written.is_some() || value != default).then_some(value)
        }
        let (env, render) = (&saved.environment, &saved.render);
        let s = &self.settings;
        let lighting = Lighting::default();
        self.look.environment = EnvironmentSettings {
            source: s.environment.clone(),
            rotation: keep(env.rotation, s.lighting.rotation_degrees, lighting.rotation_degrees),
            intensity: keep(env.intensity, s.lighting.intensity, lighting.intensity),
            background: keep(env.background, s.lighting.background, lighting.background),
            backdrop: keep(env.backdrop.as_ref(), s.backdrop.clone(), Backdrop::Environment),
        };
        self.look.render = RenderSettings {
            spp: keep(render.spp, s.spp, DEFAULT_SPP),
            seed: keep(render.seed, s.seed, 0),
            exposure: keep(render.exposure, s.exposure, 0.0),
            tonemap: keep(render.tonemap, s.tonemap, Tonemap::default()),
            // The viewer writes no AOVs; the look keeps its list for renders.
            aovs: render.aovs.clone(),
            noise_threshold: s.noise.map(|n| n.threshold),
            min_spp: s.noise.and_then(|n| keep(render.min_spp, n.min_samples, DEFAULT_MIN_SPP.min(s.spp).max(2))),
        };
        self.look.model = keep(saved.model, s.model, Model::default());
    }
}

/// Whether `object` has the stack an edit aimed at it changes, without creating one.
fn has_stack(look: &Look, object: ObjectRef) -> bool {
    look.objects.iter().any(|o| o.is_for(object.id()))
}

/// The stack for `object`, created first when it is missing (see [`Edit`]).
fn stack_mut(look: &mut Look, object: ObjectRef) -> &mut ObjectStack {
    let id = object.id();
    let index = match look.objects.iter().position(|o| o.is_for(id)) {
        Some(index) => index,
        None => {
            let (layers, shadow_catcher) = match look.objects.iter().find(|o| o.is_default()) {
                Some(default) => (default.layers.clone(), default.shadow_catcher),
                None => (vec![Layer::filling(Params::default())], false),
            };
            look.objects.push(ObjectStack { shadow_catcher, ..ObjectStack::new(id, layers) });
            look.objects.len() - 1
        }
    };
    &mut look.objects[index]
}

/// Checks that `layer` is an index into a stack of `count` layers.
pub(super) fn check_layer(object: ObjectRef, layer: usize, count: usize) -> Result<(), String> {
    if layer < count {
        Ok(())
    } else {
        let plural = if count == 1 { "" } else { "s" };
        Err(format!(
            "{object} has {count} layer{plural}; there is no layer {layer} (layers count from 0 at the bottom)"
        ))
    }
}

/// Puts a new layer of `preset` (a name or path, resolved by `presets`) at index `at` of the
/// stack, `at` = the number of layers being the top.
fn insert_layer(
    stack: &mut ObjectStack,
    object: ObjectRef,
    preset: String,
    at: usize,
    presets: Presets,
) -> Result<(), String> {
    if preset.trim().is_empty() {
        return Err("a layer's preset must not be empty".to_string());
    }
    let count = stack.layers.len();
    if at > count {
        return Err(format!("{object} has {count} layers; a new layer goes at 0 to {count} (on top)"));
    }
    let params = presets(&preset)?;
    stack.layers.insert(at, Layer { preset: Some(preset), params, ..Layer::filling(Params::default()) });
    Ok(())
}

fn layer_mut(stack: &mut ObjectStack, object: ObjectRef, layer: usize) -> Result<&mut Layer, String> {
    check_layer(object, layer, stack.layers.len())?;
    Ok(&mut stack.layers[layer])
}
