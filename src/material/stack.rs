//! Layer stacks in their GPU form: one stack per object id found in the g-buffer, its layers
//! with their own materials and map bindings, and the g-buffer channels (masks and maps) they
//! use. `resolve.comp` blends them per pixel; the CPU [`PackedStacks::resolve_pixel`] mirrors it
//! for tests and for inspecting pixels.

use super::look::{Layer, Look, ObjectStack};
use super::mask::MaskAdjust;
use super::params::{Param, Params, GPU_FLOATS};
use crate::gbuffer::{GBuffer, MapSource, MAP_PREFIX, MASK_PREFIX};
use crate::{Error, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// No channel: a layer without a mask, or a value bound to no map.
const NONE: i32 = -1;

/// One layer as `resolve.comp` reads it: twelve RGBA32_UINT texels of its `layers` image, in
/// this order, floats as their bits (texels 0–4 `params`, 5–9 `maps`, 10 the mask's channel,
/// invert and opacity, 11 its levels).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuLayer {
    pub params: [f32; GPU_FLOATS],
    /// Per value of `params`: the index into [`PackedStacks::channels`] of the map it is
    /// multiplied by, or −1.
    pub maps: [i32; GPU_FLOATS],
    /// Index into [`PackedStacks::channels`], or −1 for none (1 everywhere).
    pub mask: i32,
    pub invert: u32,
    pub opacity: f32,
    pub pad: u32,
    /// The mask's levels ([`MaskAdjust`]): black point, white point, gamma, and 1 where they
    /// change something (0: the mask is used as it is).
    pub levels: [f32; 4],
}

const _: () = assert!(std::mem::size_of::<GpuLayer>() == LAYER_TEXELS * 16);

/// Texels of `resolve.comp`'s `layers` image per layer.
pub const LAYER_TEXELS: usize = 12;

/// [`GpuLayer::levels`] of a layer whose mask is used as it is.
const NO_LEVELS: [f32; 4] = [0.0, 1.0, 1.0, 0.0];

fn gpu_levels(adjust: &MaskAdjust) -> [f32; 4] {
    if adjust.levels_are_identity() {
        NO_LEVELS
    } else {
        [adjust.black, adjust.white, adjust.gamma, 1.0]
    }
}

impl GpuLayer {
    /// A lone layer of the default parameters, for objects no stack covers.
    fn default_material() -> GpuLayer {
        GpuLayer {
            params: Params::default().to_gpu(),
            maps: [NONE; GPU_FLOATS],
            mask: NONE,
            invert: 0,
            opacity: 1.0,
            pad: 0,
            levels: NO_LEVELS,
        }
    }

    /// The mask value `m` after the layer's levels, as `resolve.comp`'s `mask_levels`.
    fn levelled(&self, m: f32) -> f32 {
        let [black, white, gamma, on] = self.levels;
        if on == 0.0 {
            return m;
        }
        MaskAdjust { black, white, gamma, blur: 0.0 }.levels(m)
    }

    /// The layer's material at a pixel whose channel values `channel_value` gives: its own
    /// values, each one bound to a map multiplied by the map's value.
    fn material(&self, channel_value: &impl Fn(usize) -> f32) -> Params {
        let values = std::array::from_fn(|k| match self.maps[k] {
            NONE => self.params[k],
            channel => self.params[k] * channel_value(channel as usize),
        });
        Params::from_gpu(&values)
    }
}

/// The look's name in messages: its file, or "built-in look".
fn look_name(look: &Look) -> String {
    look.file.as_deref().map(|p| p.display().to_string()).unwrap_or_else(|| "built-in look".into())
}

/// Every mask the look names, on any layer of any stack, must be in the g-buffer. Disabled layers
/// count too, so that enabling one is never what breaks a render.
fn check_masks(look: &Look, gbuffer: &GBuffer, gbuffer_name: &Path) -> Result<()> {
    for layer in look.objects.iter().flat_map(|o| &o.layers) {
        let Some(name) = layer.mask.as_ref().filter(|m| !gbuffer.masks.contains_key(*m)) else {
            continue;
        };
        let has = if gbuffer.masks.is_empty() {
            "no masks".to_string()
        } else {
            gbuffer.masks.keys().map(|m| format!("{MASK_PREFIX}{m}")).collect::<Vec<_>>().join(", ")
        };
        return Err(Error::input_file(
            format!("{}:{}", look_name(look), layer.line),
            format!("mask '{name}' is not in the g-buffer {} (it has {has})", gbuffer_name.display()),
        ));
    }
    Ok(())
}

/// The g-buffer channels (without the `map.` prefix) a parameter bound to `map` reads, one per
/// value of the parameter: three for a colour, where one channel stands for a grey. The error
/// says what is wrong, naming the g-buffer file and the maps it has.
fn bound_channels(
    param: Param,
    map: &str,
    gbuffer: &GBuffer,
    gbuffer_name: &Path,
) -> std::result::Result<Vec<String>, String> {
    let values = if param.is_color() { 3 } else { 1 };
    let file = gbuffer_name.display();
    match gbuffer.map_source(map) {
        Some(MapSource::Channel(channel)) => Ok(vec![channel; values]),
        Some(MapSource::Color(trio)) if param.is_color() => Ok(trio.to_vec()),
        Some(MapSource::Color(_)) => Err(format!(
            "map '{map}' of the g-buffer {file} is a colour map, and {param} is a number: bind one channel of it, such as '{map}.G'"
        )),
        None => {
            let names: Vec<String> = gbuffer.maps().into_iter().map(|m| m.name).collect();
            let candidates: Vec<&str> = names.iter().map(String::as_str).collect();
            let hint = crate::suggest::near_miss(map, &candidates).map(|n| format!("; did you mean '{n}'?")).unwrap_or_default();
            Err(format!("map '{map}' (bound to {param}) is not in the g-buffer {file} (it has {}){hint}", gbuffer.map_list()))
        }
    }
}

/// Whether a parameter can be bound to `map` of this g-buffer: the error says why not, naming
/// the file and the maps it has.
pub fn check_binding(
    param: Param,
    map: &str,
    gbuffer: &GBuffer,
    gbuffer_name: &Path,
) -> std::result::Result<(), String> {
    bound_channels(param, map, gbuffer, gbuffer_name).map(|_| ())
}

/// The maps of this g-buffer a parameter can be bound to, as a binding names them: for a colour,
/// the colour maps, then every channel (as a grey); for a number, every channel.
pub fn bindable_maps(param: Param, gbuffer: &GBuffer) -> Vec<String> {
    let colours = gbuffer.maps().into_iter().filter(|m| m.color && param.is_color()).map(|m| m.name);
    colours.chain(gbuffer.maps.keys().cloned()).collect()
}

/// Every map binding of the look, on any layer of any stack (disabled ones too, as for masks),
/// must name a map of the g-buffer that fits its parameter.
fn check_maps(look: &Look, gbuffer: &GBuffer, gbuffer_name: &Path) -> Result<()> {
    for layer in look.objects.iter().flat_map(|o| &o.layers) {
        for (&param, map) in &layer.maps {
            bound_channels(param, map, gbuffer, gbuffer_name)
                .map_err(|problem| Error::input_file(format!("{}:{}", look_name(look), layer.line), problem))?;
        }
    }
    Ok(())
}

/// Warnings for the look's stacks whose object id is not among `object_ids` (the g-buffer's
/// shaded objects): those stacks can never show, which is usually a typo in the id.
pub fn unused_stack_warnings(look: &Look, object_ids: &[u32], gbuffer_name: &Path) -> Vec<String> {
    let look_name = look_name(look);
    look.objects
        .iter()
        .filter_map(|stack| {
            let id = stack.id.filter(|id| !object_ids.contains(id))?;
            let line = stack.layers.first().map(|l| l.line).unwrap_or_default();
            Some(format!(
                "{look_name}:{line}: object id {id} is not in the g-buffer {}; its stack is unused",
                gbuffer_name.display()
            ))
        })
        .collect()
}

/// One stack as `resolve.comp` reads it, one RGBA32_UINT texel of its `stacks` image: its first
/// layer, how many layers it has, and whether its object catches shadows (1) or not (0).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuStack {
    pub first_layer: u32,
    pub layer_count: u32,
    pub shadow_catcher: u32,
    pub pad: u32,
}

const _: () = assert!(std::mem::size_of::<GpuStack>() == 16);

/// Every stack the g-buffer's objects need, ready to upload.
#[derive(Clone, Debug, PartialEq)]
pub struct PackedStacks {
    pub stacks: Vec<GpuStack>,
    pub layers: Vec<GpuLayer>,
    /// The g-buffer channels the layers use, masks and maps by their full channel names
    /// (`mask.stripes`, `map.baseColor.R`), in the order of the GPU's channel layers.
    pub channels: Vec<String>,
    /// Object id → index into `stacks`.
    pub stack_of_object: BTreeMap<u32, u32>,
}

impl PackedStacks {
    /// Packs the look's stacks for the objects in `object_ids` (those that are shaded). Disabled
    /// layers are left out, so the lowest enabled layer is the one that fills. An object with
    /// neither its own stack nor a default stack, or whose layers are all disabled, gets the
    /// default parameters. A mask or map the look names that `gbuffer` lacks, or a map that does
    /// not fit its parameter, is an error naming both files and the layer's line. Stack 0 always
    /// exists, for the pixels that shade nothing.
    pub fn pack(
        look: &Look,
        object_ids: impl IntoIterator<Item = u32>,
        gbuffer: &GBuffer,
        gbuffer_name: &Path,
    ) -> Result<PackedStacks> {
        check_masks(look, gbuffer, gbuffer_name)?;
        check_maps(look, gbuffer, gbuffer_name)?;
        let mut packed = PackedStacks {
            stacks: Vec::new(),
            layers: Vec::new(),
            channels: Vec::new(),
            stack_of_object: BTreeMap::new(),
        };
        for id in object_ids {
            let first_layer = packed.layers.len() as u32;
            let stack = look.stack_for(id);
            let layers: Vec<&Layer> =
                stack.map(|s| s.layers.iter().filter(|l| l.enabled).collect()).unwrap_or_default();
            let shadow_catcher = stack.is_some_and(|s| s.shadow_catcher) as u32;
            for (i, layer) in layers.iter().enumerate() {
                // The bottom layer fills: its mask has no effect.
                let mask = match &layer.mask {
                    Some(name) if i > 0 => {
                        packed.channel_index(&format!("{MASK_PREFIX}{}", layer.mask_adjust.channel_key(name)))
                    }
                    _ => NONE,
                };
                let mut maps = [NONE; GPU_FLOATS];
                for (&param, map) in &layer.maps {
                    let channels =
                        bound_channels(param, map, gbuffer, gbuffer_name).expect("check_maps() checked the maps");
                    for (k, channel) in channels.iter().enumerate() {
                        maps[param.gpu_index() + k] = packed.channel_index(&format!("{MAP_PREFIX}{channel}"));
                    }
                }
                packed.layers.push(GpuLayer {
                    params: layer.params.to_gpu(),
                    maps,
                    mask,
                    invert: layer.invert as u32,
                    opacity: layer.opacity,
                    pad: 0,
                    levels: if mask == NONE { NO_LEVELS } else { gpu_levels(&layer.mask_adjust) },
                });
            }
            // An object with neither its own stack nor a default one, or with every layer
            // disabled, gets the default material.
            if layers.is_empty() {
                packed.layers.push(GpuLayer::default_material());
            }
            let layer_count = packed.layers.len() as u32 - first_layer;
            packed.stack_of_object.insert(id, packed.stacks.len() as u32);
            packed.stacks.push(GpuStack { first_layer, layer_count, shadow_catcher, pad: 0 });
        }
        // Pixels that shade nothing still index a stack; with no shaded object at all, that is
        // a default-material stack.
        if packed.stacks.is_empty() {
            packed.layers.push(GpuLayer::default_material());
            packed.stacks.push(GpuStack { first_layer: 0, layer_count: 1, shadow_catcher: 0, pad: 0 });
        }
        Ok(packed)
    }

    /// Which lobes some pixel these stacks resolve may have, for the relight kernel's
    /// specialisation. Resolving blends layers convexly and maps only scale a layer's value,
    /// so a clearcoat 0 in every layer resolves to 0 everywhere, and a metallic 1 with no map
    /// in every layer to exactly 1 (fl(fl(1 − w) + w) = 1 for w in [0, 1]).
    pub fn lobes(&self) -> LobesPresent {
        let metallic = Param::Metallic.gpu_index();
        let clearcoat = Param::Clearcoat.gpu_index();
        LobesPresent {
            diffuse: self.layers.iter().any(|l| l.params[metallic] != 1.0 || l.maps[metallic] != NONE),
            clearcoat: self.layers.iter().any(|l| l.params[clearcoat] != 0.0),
        }
    }

    /// Whether some object catches shadows, so the relight and finalize kernels need the
    /// unshadowed sums.
    pub fn has_shadow_catcher(&self) -> bool {
        self.stacks.iter().any(|s| s.shadow_catcher != 0)
    }

    /// The objects that catch shadows.
    pub fn shadow_catcher_objects(&self) -> std::collections::BTreeSet<u32> {
        let catches = |s: u32| self.stacks[s as usize].shadow_catcher != 0;
        self.stack_of_object.iter().filter(|(_, &s)| catches(s)).map(|(&id, _)| id).collect()
    }

    /// Whether some layer binds a map, so the resolve kernel needs its map code.
    pub fn binds_maps(&self) -> bool {
        self.layers.iter().any(|layer| layer.maps.iter().any(|&m| m != NONE))
    }

    /// Which of these stacks may resolve to another material than `before`'s did, at some
    /// pixel: every one when there was nothing before, or when pixels map to stacks differently
    /// or the layers read other channels; otherwise those whose layers differ, bit for bit.
    /// A stack marked false resolves to exactly what `before`'s did wherever it is used.
    pub fn changed_since(&self, before: Option<&PackedStacks>) -> Vec<bool> {
        fn layers_of<'a>(packed: &'a PackedStacks, stack: &GpuStack) -> &'a [u8] {
            let first = stack.first_layer as usize;
            bytemuck::cast_slice(&packed.layers[first..first + stack.layer_count as usize])
        }
        match before {
            Some(b) if b.stack_of_object == self.stack_of_object && b.channels == self.channels => self
                .stacks
                .iter()
                .enumerate()
                .map(|(i, stack)| {
                    b.stacks.get(i).is_none_or(|old| {
                        layers_of(b, old) != layers_of(self, stack) || old.shadow_catcher != stack.shadow_catcher
                    })
                })
                .collect(),
            _ => vec![true; self.stacks.len()],
        }
    }

    /// The GPU channel layer of a g-buffer channel, added on first use.
    fn channel_index(&mut self, channel: &str) -> i32 {
        let index = self.channels.iter().position(|c| c == channel).unwrap_or_else(|| {
            self.channels.push(channel.to_string());
            self.channels.len() - 1
        });
        index as i32
    }

    /// The blended material of one pixel, as `resolve.comp` computes it; `channel_value(i)` is
    /// the pixel's value of `channels[i]`.
    pub fn resolve_pixel(&self, object_id: u32, channel_value: impl Fn(usize) -> f32) -> Params {
        let stack = self.stacks[self.stack_of_object[&object_id] as usize];
        let layers = &self.layers[stack.first_layer as usize..(stack.first_layer + stack.layer_count) as usize];
        let mut params = layers[0].material(&channel_value);
        for layer in &layers[1..] {
            let m = if layer.mask >= 0 { layer.levelled(channel_value(layer.mask as usize)) } else { 1.0 };
            let w = (layer.opacity * if layer.invert != 0 { 1.0 - m } else { m }).clamp(0.0, 1.0);
            params = params.mix(&layer.material(&channel_value), w);
        }
        params
    }

    /// [`PackedStacks::resolve_pixel`] at pixel `index` of the g-buffer the stacks were packed for.
    pub fn resolve_gbuffer_pixel(&self, gbuffer: &GBuffer, index: usize) -> Params {
        let channel_value = |i: usize| gbuffer.stack_channel_at(&self.channels[i], index).unwrap_or(0.0);
        self.resolve_pixel(gbuffer.object_id[index], channel_value)
    }
}

/// The lobes a scene's materials may have somewhere ([`PackedStacks::lobes`]): the relight
/// kernel is specialised for them (`SCENE_DIFFUSE`, `SCENE_CLEARCOAT` in `brdf.glsl`), so that
/// it leaves out the code of lobes no pixel has. Images differ from those of a kernel with every
/// lobe only by float rounding (the compiler may fuse what remains differently).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LobesPresent {
    /// Some pixel's metallic is below 1: the diffuse, subsurface and sheen lobes.
    pub diffuse: bool,
    /// Some pixel's clearcoat is above 0.
    pub clearcoat: bool,
}

impl Default for LobesPresent {
    /// Every lobe: right for any scene.
    fn default() -> Self {
        LobesPresent { diffuse: true, clearcoat: true }
    }
}

/// How much one layer counts at a pixel, as `resolve.comp` blends the stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerWeight {
    /// The layer's blend weight: 1 for the bottom (filling) layer, else opacity × mask value
    /// (or 1 − mask value, inverted), clamped to [0, 1].
    pub blend: f32,
    /// The share of the result that is this layer's: its blend weight times what the layers
    /// above it leave. The shares of a stack sum to 1.
    pub contribution: f32,
}

/// Each layer's weight at a pixel whose mask values `mask_value` gives by channel key (the
/// mask's name, or a blurred mask's key: [`MaskAdjust::channel_key`]); `None` for a disabled
/// layer. Levels apply here. The same rule as [`PackedStacks::pack`] and `resolve.comp`: the lowest enabled
/// layer fills, and each layer above mixes over the result of those below.
pub fn layer_weights(stack: &ObjectStack, mask_value: impl Fn(&str) -> f32) -> Vec<Option<LayerWeight>> {
    let mut weights: Vec<Option<LayerWeight>> = vec![None; stack.layers.len()];
    let enabled: Vec<usize> = (0..stack.layers.len()).filter(|&i| stack.layers[i].enabled).collect();
    let mut remaining = 1.0;
    for (rank, &i) in enabled.iter().enumerate().rev() {
        let layer = &stack.layers[i];
        let blend = match &layer.mask {
            _ if rank == 0 => 1.0,
            Some(name) => {
                let m = layer.mask_adjust.levels(mask_value(&layer.mask_adjust.channel_key(name)));
                (layer.opacity * if layer.invert { 1.0 - m } else { m }).clamp(0.0, 1.0)
            }
            None => layer.opacity.clamp(0.0, 1.0),
        };
        weights[i] = Some(LayerWeight { blend, contribution: blend * remaining });
        remaining *= 1.0 - blend;
    }
    weights
}

/// The mask channels a stack's layers read, by the key [`layer_weights`] asks for (blurred
/// masks made once here), for callers that weigh the layers at many pixels.
pub fn mask_channels<'g>(stack: &ObjectStack, gbuffer: &'g GBuffer) -> BTreeMap<String, std::borrow::Cow<'g, [f32]>> {
    let keys = stack.layers.iter().filter_map(|l| l.mask.as_ref().map(|m| l.mask_adjust.channel_key(m)));
    keys.filter_map(|key| Some((key.clone(), gbuffer.stack_channel(&format!("{MASK_PREFIX}{key}"))?))).collect()
}

/// Each layer's share of the blend ([`LayerWeight::contribution`]) at every pixel that `stack`
/// of `look` shades, 0 elsewhere: the matte of where each layer shows, as the `layers` AOVs
/// and the viewer's mask overlay give it.
pub fn layer_shares(look: &Look, stack: &ObjectStack, gbuffer: &GBuffer) -> Vec<Vec<f32>> {
    let mut values = vec![vec![0.0f32; gbuffer.pixel_count()]; stack.layers.len()];
    let masks = mask_channels(stack, gbuffer);
    for p in 0..gbuffer.pixel_count() {
        let shades = look.stack_for(gbuffer.object_id[p]).unwrap_or(stack);
        if gbuffer.coverage[p] <= 0.0 || !std::ptr::eq(shades, stack) {
            continue;
        }
        let mask = |key: &str| masks.get(key).map_or(0.0, |m| m[p]);
        for (i, weight) in layer_weights(stack, mask).into_iter().enumerate() {
            values[i][p] = weight.map_or(0.0, |w| w.contribution);
        }
    }
    values
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(roughness: f32, mask: Option<&str>, enabled: bool) -> Layer {
        Layer {
            params: Params { roughness, ..Params::default() },
            mask: mask.map(String::from),
            opacity: 0.5,
            enabled,
            ..Layer::filling(Params::default())
        }
    }

    /// A one-pixel g-buffer with masks `stripes` and `grunge`, the colour map `tex` and the
    /// scalar map `rough`.
    fn gbuffer() -> GBuffer {
        let mut gbuffer = GBuffer::shaderball(1, 1);
        gbuffer.object_id = vec![1];
        gbuffer.masks = [("stripes", 0.8), ("grunge", 0.25)].map(|(n, v)| (n.to_string(), vec![v])).into();
        gbuffer.maps = [("tex.R", 0.5), ("tex.G", 0.25), ("tex.B", 0.125), ("rough", 0.4)]
            .map(|(n, v)| (n.to_string(), vec![v]))
            .into();
        gbuffer
    }

    fn look(layers: Vec<Layer>) -> Look {
        let mut look = Look::default_material();
        look.objects = vec![ObjectStack::new(Some(1), layers)];
        look
    }

    fn pack(layers: Vec<Layer>) -> PackedStacks {
        PackedStacks::pack(&look(layers), [1], &gbuffer(), Path::new("test.exr")).unwrap()
    }

    fn pack_error(layers: Vec<Layer>) -> String {
        PackedStacks::pack(&look(layers), [1], &gbuffer(), Path::new("test.exr")).unwrap_err().to_string()
    }

    #[test]
    fn bound_values_are_the_layers_times_the_maps_and_blend_as_before() {
        let mut bottom = layer(0.5, None, true);
        bottom.params.base_color = [0.8, 0.6, 1.0];
        bottom.maps = [(Param::BaseColor, "tex".to_string()), (Param::Roughness, "rough".to_string())].into();
        let mut top = layer(0.9, Some("stripes"), true);
        top.params.emission = [2.0, 4.0, 8.0];
        top.maps = [(Param::Emission, "tex.G".to_string()), (Param::Metallic, "tex.B".to_string())].into();
        top.params.metallic = 1.0;
        let packed = pack(vec![bottom, top]);
        assert_eq!(packed.channels, ["map.tex.R", "map.tex.G", "map.tex.B", "map.rough", "mask.stripes"]);
        let g = gbuffer();
        let p = packed.resolve_gbuffer_pixel(&g, 0);
        let w = 0.5 * 0.8;
        let mixed = |a: f32, b: f32| a * (1.0 - w) + b * w;
        assert!(
            (p.base_color[0] - mixed(0.8 * 0.5, 0.8)).abs() < 1e-6,
            "the bottom's base colour × map, under the top's"
        );
        assert!((p.base_color[2] - mixed(1.0 * 0.125, 0.8)).abs() < 1e-6, "{:?}", p.base_color);
        assert!((p.roughness - mixed(0.5 * 0.4, 0.9)).abs() < 1e-6, "{}", p.roughness);
        assert!((p.metallic - mixed(0.0, 0.125)).abs() < 1e-6, "{}", p.metallic);
        // One channel of a colour map is a grey for a colour parameter.
        for (c, e) in [2.0f32, 4.0, 8.0].into_iter().enumerate() {
            assert!((p.emission[c] - mixed(0.0, e * 0.25)).abs() < 1e-6, "{:?}", p.emission);
        }
    }

    #[test]
    fn a_stack_changes_when_its_layers_or_what_they_read_do() {
        // Objects 1 and 2, each with its own stack.
        let pack2 = |ball: Vec<Layer>, pedestal: Vec<Layer>| {
            let mut look = Look::default_material();
            look.objects = vec![ObjectStack::new(Some(1), ball), ObjectStack::new(Some(2), pedestal)];
            let mut g = gbuffer();
            g.object_id = vec![1];
            PackedStacks::pack(&look, [1, 2], &g, Path::new("test.exr")).unwrap()
        };
        let before = pack2(vec![layer(0.5, None, true)], vec![layer(0.2, None, true)]);
        assert_eq!(before.changed_since(None), [true, true], "nothing resolved yet");
        assert_eq!(before.changed_since(Some(&before)), [false, false]);
        let rougher = pack2(vec![layer(0.6, None, true)], vec![layer(0.2, None, true)]);
        assert_eq!(rougher.changed_since(Some(&before)), [true, false]);
        // A layer more in the first stack moves the second's layers, not their contents.
        let two = pack2(vec![layer(0.5, None, true), layer(0.9, None, true)], vec![layer(0.2, None, true)]);
        assert_eq!(two.changed_since(Some(&before)), [true, false]);
        // -0 and 0 resolve to different bits: compared as bits, they differ.
        let negative_zero = pack2(vec![layer(0.5, None, true)], vec![layer(-0.0, None, true)]);
        let zero = pack2(vec![layer(0.5, None, true)], vec![layer(0.0, None, true)]);
        assert_eq!(negative_zero.changed_since(Some(&zero)), [false, true]);
        // Another channel list renumbers every layer's masks and maps: all change.
        let grunge =
            pack2(vec![layer(0.5, None, true)], vec![layer(0.2, None, true), layer(0.3, Some("grunge"), true)]);
        let both = pack2(
            vec![layer(0.5, None, true), layer(0.9, Some("stripes"), true)],
            vec![layer(0.2, None, true), layer(0.3, Some("grunge"), true)],
        );
        assert_eq!(both.changed_since(Some(&grunge)), [true, true]);
        // Objects mapped to other stacks: all change.
        let mut swapped = before.clone();
        swapped.stack_of_object = [(1, 1), (2, 0)].into();
        assert_eq!(swapped.changed_since(Some(&before)), [true, true]);
    }

    #[test]
    fn the_lobes_present_are_those_some_enabled_layer_can_give_a_pixel() {
        let metal = |clearcoat: f32, enabled: bool| {
            let mut l = layer(0.3, Some("stripes"), enabled);
            (l.params.metallic, l.params.clearcoat) = (1.0, clearcoat);
            l
        };
        let lobes = |layers| pack(layers).lobes();
        let none = LobesPresent { diffuse: false, clearcoat: false };
        assert_eq!(lobes(vec![metal(0.0, true), metal(0.0, true)]), none, "metals blend to metallic 1");
        assert_eq!(lobes(vec![metal(0.0, true), metal(0.5, false)]), none, "a disabled layer gives nothing");
        assert_eq!(lobes(vec![metal(0.0, true), metal(0.5, true)]), LobesPresent { clearcoat: true, ..none });
        assert_eq!(lobes(vec![metal(0.0, true), layer(0.3, None, true)]), LobesPresent { diffuse: true, ..none });
        // A map only scales a value: it can take metallic below 1, but not clearcoat above 0.
        let mut mapped = metal(0.0, true);
        mapped.maps = [(Param::Metallic, "rough".to_string()), (Param::Clearcoat, "rough".to_string())].into();
        assert_eq!(lobes(vec![mapped]), LobesPresent { diffuse: true, ..none });
        // fl(fl(1 − w) + w) = 1 for every weight: what makes metals blend to exactly 1.
        for k in 0..=1_000_000u32 {
            let w = k as f32 / 1_000_000.0;
            assert_eq!(1.0f32 * (1.0 - w) + 1.0 * w, 1.0, "w = {w}");
        }
    }

    #[test]
    fn a_binding_the_gbuffer_cannot_satisfy_is_an_error_naming_what_it_has() {
        let mut bound = layer(0.5, None, true);
        bound.line = 7;
        bound.maps = [(Param::BaseColor, "texx".to_string())].into();
        let message = pack_error(vec![bound.clone()]);
        assert!(
            message.starts_with("built-in look:7: map 'texx' (bound to base_color) is not in the g-buffer test.exr")
        );
        assert!(message.contains("(it has map.rough, map.tex.R/G/B); did you mean 'tex'?"), "{message}");

        bound.maps = [(Param::Roughness, "tex".to_string())].into();
        let message = pack_error(vec![bound.clone()]);
        assert!(message.contains("is a colour map, and roughness is a number"), "{message}");
        assert!(message.contains("'tex.G'"), "{message}");

        // A disabled layer's binding is checked too.
        bound.maps = [(Param::Metallic, "nope".to_string())].into();
        bound.enabled = false;
        assert!(pack_error(vec![layer(0.1, None, true), bound]).contains("map 'nope'"));
    }

    #[test]
    fn disabled_layers_are_left_out_and_the_lowest_enabled_layer_fills() {
        // Bottom disabled: the striped layer becomes the bottom, so its mask no longer applies.
        let packed =
            pack(vec![layer(0.1, None, false), layer(0.2, Some("stripes"), true), layer(0.3, Some("grunge"), true)]);
        assert_eq!(packed.stacks[0].layer_count, 2);
        let roughness: Vec<f32> = packed.layers.iter().map(|l| Params::from_gpu(&l.params).roughness).collect();
        assert_eq!(roughness, [0.2, 0.3]);
        assert_eq!(packed.layers[0].mask, -1, "the filling layer's mask has no effect");
        assert_eq!(packed.channels, ["mask.grunge"], "a mask used only as the fill is not bound");
        assert_eq!(packed.resolve_pixel(1, |_| 0.0).roughness, 0.2, "the new bottom fills where the mask is 0");

        // A disabled layer in the middle simply drops out.
        let packed =
            pack(vec![layer(0.1, None, true), layer(0.2, Some("stripes"), false), layer(0.3, Some("grunge"), true)]);
        let roughness: Vec<f32> = packed.layers.iter().map(|l| Params::from_gpu(&l.params).roughness).collect();
        assert_eq!(roughness, [0.1, 0.3]);
        assert_eq!(packed.channels, ["mask.grunge"]);

        // Every layer disabled: one layer of the default material.
        let packed = pack(vec![layer(0.1, None, false), layer(0.2, Some("stripes"), false)]);
        assert_eq!(packed.stacks[0].layer_count, 1);
        assert_eq!(packed.layers, [GpuLayer::default_material()]);
        assert_eq!(packed.resolve_pixel(1, |_| 1.0), Params::default());
    }

    #[test]
    fn layer_weights_share_the_result_as_resolve_blends_it() {
        let mut layers =
            vec![layer(0.1, None, true), layer(0.5, Some("stripes"), true), layer(0.9, Some("grunge"), true)];
        layers[2].invert = true;
        layers.insert(1, layer(0.7, None, false));
        let stack = ObjectStack::new(Some(1), layers.clone());
        let masks = |name: &str| if name == "stripes" { 0.8 } else { 0.25 };
        let weights = layer_weights(&stack, masks);
        assert_eq!(weights[1], None, "a disabled layer has no weight");
        let w: Vec<LayerWeight> = weights.iter().flatten().copied().collect();
        assert_eq!(w[0].blend, 1.0, "the bottom layer fills");
        assert!((w[1].blend - 0.5 * 0.8).abs() < 1e-6);
        assert!((w[2].blend - 0.5 * 0.75).abs() < 1e-6, "inverted: opacity × (1 − mask)");
        let total: f32 = w.iter().map(|w| w.contribution).sum();
        assert!((total - 1.0).abs() < 1e-6, "shares sum to 1, got {total}");

        let packed = pack(layers.clone());
        let resolved = packed.resolve_pixel(1, |i| masks(&packed.channels[i]["mask.".len()..])).roughness;
        let enabled: Vec<&Layer> = layers.iter().filter(|l| l.enabled).collect();
        let shared: f32 = enabled.iter().zip(&w).map(|(l, w)| l.params.roughness * w.contribution).sum();
        assert!((resolved - shared).abs() < 1e-6, "resolve gives {resolved}, the shares {shared}");
    }
}
