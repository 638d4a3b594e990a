//! Layer stacks in their GPU form: one stack per object id found in the g-buffer, its layers
//! with their own materials, and the masks they use. `resolve.comp` blends them per pixel; the
//! CPU [`PackedStacks::resolve_pixel`] mirrors it for tests and for inspecting pixels.

use super::look::{Layer, Look, ObjectStack};
use super::params::Params;
use crate::{Error, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// One layer as `resolve.comp` reads it (std430, 80 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuLayer {
    pub params: [f32; 16],
    /// Index into [`PackedStacks::masks`], or −1 for none (1 everywhere).
    pub mask: i32,
    pub invert: u32,
    pub opacity: f32,
    pub pad: u32,
}

impl GpuLayer {
    /// A lone layer of the default parameters, for objects no stack covers.
    fn default_material() -> GpuLayer {
        GpuLayer { params: Params::default().to_gpu(), mask: -1, invert: 0, opacity: 1.0, pad: 0 }
    }
}

/// Every mask the look names, on any layer of any stack, must be in the g-buffer. Disabled layers
/// count too, so that enabling one is never what breaks a render.
fn check_masks(look: &Look, look_name: &str, available: &[String], gbuffer_name: &Path) -> Result<()> {
    for layer in look.objects.iter().flat_map(|o| &o.layers) {
        let Some(name) = layer.mask.as_ref().filter(|m| !available.contains(m)) else {
            continue;
        };
        let has = if available.is_empty() {
            "no masks".to_string()
        } else {
            available.iter().map(|m| format!("mask.{m}")).collect::<Vec<_>>().join(", ")
        };
        return Err(Error::input_file(
            format!("{look_name}:{}", layer.line),
            format!("mask '{name}' is not in the g-buffer {} (it has {has})", gbuffer_name.display()),
        ));
    }
    Ok(())
}

/// Warnings for the look's stacks whose object id is not among `object_ids` (the g-buffer's
/// shaded objects): those stacks can never show, which is usually a typo in the id.
pub fn unused_stack_warnings(look: &Look, object_ids: &[u32], gbuffer_name: &Path) -> Vec<String> {
    let look_name = look.file.as_deref().map(|p| p.display().to_string()).unwrap_or_else(|| "built-in look".into());
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

/// One stack as `resolve.comp` reads it: its first layer and how many layers it has.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuStack {
    pub first_layer: u32,
    pub layer_count: u32,
    pub pad: [u32; 2],
}

/// Every stack the g-buffer's objects need, ready to upload.
#[derive(Clone, Debug, PartialEq)]
pub struct PackedStacks {
    pub stacks: Vec<GpuStack>,
    pub layers: Vec<GpuLayer>,
    /// The g-buffer masks the layers use, in the order of the GPU's mask layers.
    pub masks: Vec<String>,
    /// Object id → index into `stacks`.
    pub stack_of_object: BTreeMap<u32, u32>,
}

impl PackedStacks {
    /// Packs the look's stacks for the objects in `object_ids` (those that are shaded). Disabled
    /// layers are left out, so the lowest enabled layer is the one that fills. An object with
    /// neither its own stack nor a default stack, or whose layers are all disabled, gets the
    /// default parameters. A mask the look names that `available_masks` lacks is an error
    /// naming both files and the layer's line. Stack 0 always exists, for the pixels that shade
    /// nothing.
    pub fn pack(
        look: &Look,
        object_ids: impl IntoIterator<Item = u32>,
        available_masks: &[String],
        gbuffer_name: &Path,
    ) -> Result<PackedStacks> {
        let look_name = look.file.as_deref().map(|p| p.display().to_string()).unwrap_or_else(|| "built-in look".into());
        check_masks(look, &look_name, available_masks, gbuffer_name)?;
        let mut packed = PackedStacks {
            stacks: Vec::new(),
            layers: Vec::new(),
            masks: Vec::new(),
            stack_of_object: BTreeMap::new(),
        };
        for id in object_ids {
            let first_layer = packed.layers.len() as u32;
            let layers: Vec<&Layer> =
                look.stack_for(id).map(|s| s.layers.iter().filter(|l| l.enabled).collect()).unwrap_or_default();
            for (i, layer) in layers.iter().enumerate() {
                // The bottom layer fills: its mask has no effect.
                let mask = match &layer.mask {
                    Some(name) if i > 0 => packed.mask_index(name) as i32,
                    _ => -1,
                };
                packed.layers.push(GpuLayer {
                    params: layer.params.to_gpu(),
                    mask,
                    invert: layer.invert as u32,
                    opacity: layer.opacity,
                    pad: 0,
                });
            }
            // An object with neither its own stack nor a default one, or with every layer
            // disabled, gets the default material.
            if layers.is_empty() {
                packed.layers.push(GpuLayer::default_material());
            }
            let layer_count = packed.layers.len() as u32 - first_layer;
            packed.stack_of_object.insert(id, packed.stacks.len() as u32);
            packed.stacks.push(GpuStack { first_layer, layer_count, pad: [0; 2] });
        }
        // Pixels that shade nothing still index a stack; with no shaded object at all, that is
        // a default-material stack.
        if packed.stacks.is_empty() {
            packed.layers.push(GpuLayer::default_material());
            packed.stacks.push(GpuStack { first_layer: 0, layer_count: 1, pad: [0; 2] });
        }
        Ok(packed)
    }

    /// The GPU mask layer of a g-buffer mask, added on first use.
    fn mask_index(&mut self, name: &str) -> usize {
        self.masks.iter().position(|m| m == name).unwrap_or_else(|| {
            self.masks.push(name.to_string());
            self.masks.len() - 1
        })
    }

    /// The blended material of one pixel, as `resolve.comp` computes it; `mask_value(i)` is the
    /// pixel's value of `masks[i]`.
    pub fn resolve_pixel(&self, object_id: u32, mask_value: impl Fn(usize) -> f32) -> Params {
        let stack = self.stacks[self.stack_of_object[&object_id] as usize];
        let layers = &self.layers[stack.first_layer as usize..(stack.first_layer + stack.layer_count) as usize];
        let mut params = Params::from_gpu(&layers[0].params);
        for layer in &layers[1..] {
            let m = if layer.mask >= 0 { mask_value(layer.mask as usize) } else { 1.0 };
            let w = (layer.opacity * if layer.invert != 0 { 1.0 - m } else { m }).clamp(0.0, 1.0);
            params = params.mix(&Params::from_gpu(&layer.params), w);
        }
        params
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

/// Each layer's weight at a pixel whose mask values `mask_value` gives by name; `None` for a
/// disabled layer. The same rule as [`PackedStacks::pack`] and `resolve.comp`: the lowest enabled
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
                let m = mask_value(name);
                (layer.opacity * if layer.invert { 1.0 - m } else { m }).clamp(0.0, 1.0)
            }
            None => layer.opacity.clamp(0.0, 1.0),
        };
        weights[i] = Some(LayerWeight { blend, contribution: blend * remaining });
        remaining *= 1.0 - blend;
    }
    weights
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(roughness: f32, mask: Option<&str>, enabled: bool) -> Layer {
        Layer {
            preset: None,
            params: Params { roughness, ..Params::default() },
            overrides: Vec::new(),
            mask: mask.map(String::from),
            invert: false,
            opacity: 0.5,
            enabled,
            line: 0,
        }
    }

    fn pack(layers: Vec<Layer>) -> PackedStacks {
        let mut look = Look::default_material();
        look.objects = vec![ObjectStack { id: Some(1), layers }];
        PackedStacks::pack(&look, [1], &["stripes".to_string(), "grunge".to_string()], Path::new("test.exr")).unwrap()
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
        assert_eq!(packed.masks, ["grunge"], "a mask used only as the fill is not bound");
        assert_eq!(packed.resolve_pixel(1, |_| 0.0).roughness, 0.2, "the new bottom fills where the mask is 0");

        // A disabled layer in the middle simply drops out.
        let packed =
            pack(vec![layer(0.1, None, true), layer(0.2, Some("stripes"), false), layer(0.3, Some("grunge"), true)]);
        let roughness: Vec<f32> = packed.layers.iter().map(|l| Params::from_gpu(&l.params).roughness).collect();
        assert_eq!(roughness, [0.1, 0.3]);
        assert_eq!(packed.masks, ["grunge"]);

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
        let stack = ObjectStack { id: Some(1), layers: layers.clone() };
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
        let resolved = packed.resolve_pixel(1, |i| masks(&packed.masks[i])).roughness;
        let enabled: Vec<&Layer> = layers.iter().filter(|l| l.enabled).collect();
        let shared: f32 = enabled.iter().zip(&w).map(|(l, w)| l.params.roughness * w.contribution).sum();
        assert!((resolved - shared).abs() < 1e-6, "resolve gives {resolved}, the shares {shared}");
    }
}
