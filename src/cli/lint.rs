//! `lookdev lint LOOK.toml [--gbuffer G.exr]`: implausible material values, each with its reason.
//!
//! Every layer's resolved parameters (its preset with its overrides) are checked. A parameter
//! bound to a map holds a factor, not a value, so the rules that read it are left out; with
//! `--gbuffer`, the masks and maps the look names must be in the g-buffer (as for a render), and
//! the bound layers are checked at every covered pixel where they show (making at least half of
//! the result), with the factor times the map: a finding there gives the share of those pixels.
//! Objects most of whose pixels see no sky through the g-buffer's visibility are findings too. A look
//! that passes prints nothing and exits 0; findings are printed one per line, `FILE:LINE: object,
//! layer: finding`, and the exit code is 1. A look or g-buffer that cannot be read is an error
//! (exit 2).

use crate::gbuffer::GBuffer;
use crate::material::look::{Layer, ObjectStack};
use crate::material::params::{Param, Params};
use crate::material::stack::{layer_weights, mask_channels, PackedStacks};
use crate::material::Look;
use crate::render::scene::covered_object_ids;
use crate::shading::common::luminance;
use crate::{Error, Result};
use clap::Args;
use glam::Vec3;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct LintArgs {
    pub look: PathBuf,
    /// With a g-buffer (--gbuffer, or the look's [gbuffer] file): check the look's masks, maps
    /// and object names against it, and the bound layers at its pixels.
    #[command(flatten)]
    pub input: super::inputs::GBufferArgs,
}

/// The rules, each reading some parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Rule {
    MetallicInBetween,
    DielectricAlbedo,
    MetalReflectance,
    SpecularAboveOne,
}

impl Rule {
    /// The parameters the rule reads: binding any of them to a map leaves it to the g-buffer.
    fn reads(self) -> &'static [Param] {
        match self {
            Rule::MetallicInBetween => &[Param::Metallic],
            Rule::DielectricAlbedo | Rule::MetalReflectance => &[Param::Metallic, Param::BaseColor],
            Rule::SpecularAboveOne => &[Param::Specular],
        }
    }
}

/// Plausible ranges, from measured materials: charcoal reflects about 4% and fresh snow about
/// 90%; the darkest common metal (by normal-incidence reflectance) is around 0.5 (iron,
/// titanium), so below 0.45 the base colour was probably meant for a dielectric; specular 1 is
/// F0 = 0.08, an IOR of 1.8, above nearly every common dielectric but gems.
pub const DIELECTRIC_ALBEDO: (f32, f32) = (0.02, 0.9);
pub const METAL_F0_MIN: f32 = 0.45;
pub const SPECULAR_MAX: f32 = 1.0;

impl Rule {
    pub const ALL: [Rule; 4] =
        [Rule::MetallicInBetween, Rule::DielectricAlbedo, Rule::MetalReflectance, Rule::SpecularAboveOne];

    /// Whether the rule finds these parameters implausible.
    pub fn fails(self, params: &Params) -> bool {
        let m = params.metallic;
        let lum = luminance(Vec3::from(params.base_color));
        match self {
            Rule::MetallicInBetween => m > 0.0 && m < 1.0,
            Rule::DielectricAlbedo => m < 0.5 && !(DIELECTRIC_ALBEDO.0..=DIELECTRIC_ALBEDO.1).contains(&lum),
            Rule::MetalReflectance => m >= 0.5 && lum < METAL_F0_MIN,
            Rule::SpecularAboveOne => params.specular > SPECULAR_MAX,
        }
    }

    /// What the rule found in parameters it fails, with the reason.
    pub fn finding(self, params: &Params) -> String {
        let m = params.metallic;
        let lum = luminance(Vec3::from(params.base_color));
        match self {
            Rule::MetallicInBetween => format!(
                "metallic = {m} is in between: a surface is a metal or it is not; blend a metal layer in through a mask instead"
            ),
            Rule::DielectricAlbedo => format!(
                "base_color luminance {lum:.3} is outside [{}, {}] for a dielectric: charcoal reflects about 0.04 and fresh snow about 0.9",
                DIELECTRIC_ALBEDO.0, DIELECTRIC_ALBEDO.1
            ),
            Rule::MetalReflectance => format!(
                "metal F0 (base_color) luminance {lum:.3} is below {METAL_F0_MIN}: darker than any common metal at normal incidence"
            ),
            Rule::SpecularAboveOne => {
                let f0 = 0.08 * params.specular;
                let ior = (1.0 + f0.sqrt()) / (1.0 - f0.sqrt());
                format!(
                    "specular = {} is above 1: F0 {f0:.3}, an IOR of {ior:.2}, more than almost any dielectric but gems",
                    params.specular
                )
            }
        }
    }
}

/// The findings for one set of parameters, with the rule behind each.
pub fn findings(params: &Params) -> Vec<(Rule, String)> {
    Rule::ALL.into_iter().filter(|r| r.fails(params)).map(|r| (r, r.finding(params))).collect()
}

/// A bound layer's findings at the g-buffer's pixels: each rule that fails at more than this
/// share of the pixels where the layer shows is reported (filtered texels in between are normal).
pub const PIXEL_SHARE: f32 = 0.01;

pub fn run(args: LintArgs) -> Result<()> {
    let mut look = Look::load(&args.look)?;
    let spec = args.input.spec()?;
    let mut count = 0;
    let gbuffer = match spec.file.is_some() || look.gbuffer.file.is_some() {
        true => {
            let read = crate::render::scene::read_gbuffer(&spec, &mut look, true)?;
            // Stacks that claim the same object are findings here, not warnings.
            for claim in read.claims {
                println!("{claim}");
                count += 1;
            }
            // The masks and maps must be there, as for a render.
            PackedStacks::pack(&look, covered_object_ids(&read.gbuffer), &read.gbuffer, &read.name)?;
            for finding in crate::render::scene::blind_objects(&read.gbuffer) {
                println!("{}: {finding}", read.name.display());
                count += 1;
            }
            let covered = covered_object_ids(&read.gbuffer);
            for finding in crate::render::scene::shadowless_catchers(&look, &covered, &read.gbuffer, &read.name) {
                println!("{finding}");
                count += 1;
            }
            Some(read.gbuffer)
        }
        false => {
            for (i, stack) in look.objects.iter().enumerate() {
                let Some(name) = &stack.name else { continue };
                if let Some(first) = look.objects[..i].iter().find(|o| o.name.as_ref() == Some(name)) {
                    println!(
                        "{}:{}: this stack claims object '{name}', which the stack at line {} claims too",
                        args.look.display(),
                        stack.line,
                        first.line
                    );
                    count += 1;
                }
            }
            None
        }
    };
    for object in &look.objects {
        let who = match (&object.name, object.id) {
            (Some(name), _) => format!("object '{name}'"),
            (None, Some(id)) => format!("object {id}"),
            (None, None) => "default stack".into(),
        };
        for (i, layer) in object.layers.iter().enumerate() {
            let name = layer.preset.as_deref().map(|p| format!(" ({p})")).unwrap_or_default();
            let mut report = |finding: String| {
                println!("{}:{}: {who}, layer {i}{name}: {finding}", args.look.display(), layer.line);
                count += 1;
            };
            let unbound = |rule: Rule| !rule.reads().iter().any(|p| layer.maps.contains_key(p));
            for (_, finding) in findings(&layer.params).into_iter().filter(|(rule, _)| unbound(*rule)) {
                report(finding);
            }
            if let Some(gbuffer) = gbuffer.as_ref().filter(|_| !layer.maps.is_empty() && layer.enabled) {
                for finding in pixel_findings(&look, object, i, gbuffer, &unbound) {
                    report(finding);
                }
            }
        }
    }
    if count > 0 {
        return Err(Error::lint(format!("{}: {count} finding(s)", args.look.display())));
    }
    Ok(())
}

/// The findings of the rules that read a bound parameter, for layer `index` of `stack`, over the
/// covered pixels of the objects that stack shades where the layer makes at least half of the
/// result (its share, after the layers above it): the layer's own material there (its values
/// times its maps), each rule reported with the share of those pixels it fails at and the first
/// failing value.
fn pixel_findings(
    look: &Look,
    stack: &ObjectStack,
    index: usize,
    gbuffer: &GBuffer,
    unbound: &dyn Fn(Rule) -> bool,
) -> Vec<String> {
    // A look of this one layer alone, filling, resolves its own material at each pixel.
    let lone = Look {
        objects: vec![ObjectStack::new(None, vec![Layer { mask: None, ..stack.layers[index].clone() }])],
        ..look.clone()
    };
    let Ok(packed) = PackedStacks::pack(&lone, covered_object_ids(gbuffer), gbuffer, std::path::Path::new("")) else {
        return Vec::new();
    };
    let rules: Vec<Rule> = Rule::ALL.into_iter().filter(|&r| !unbound(r)).collect();
    let mut shown = 0usize;
    // Per rule: the pixels it fails at, and the material at the first of them.
    let mut failed: Vec<(usize, Option<Params>)> = vec![(0, None); rules.len()];
    let masks = mask_channels(stack, gbuffer);
    for p in 0..gbuffer.pixel_count() {
        let id = gbuffer.object_id[p];
        if gbuffer.coverage[p] <= 0.0 || !look.stack_for(id).is_some_and(|s| std::ptr::eq(s, stack)) {
            continue;
        }
        let mask_value = |key: &str| masks.get(key).map_or(0.0, |m| m[p]);
        if layer_weights(stack, mask_value)[index].is_none_or(|w| w.contribution < 0.5) {
            continue;
        }
        shown += 1;
        let params = packed.resolve_gbuffer_pixel(gbuffer, p);
        for (rule, (count, first)) in rules.iter().zip(failed.iter_mut()) {
            if rule.fails(&params) {
                *count += 1;
                first.get_or_insert(params);
            }
        }
    }
    rules
        .iter()
        .zip(failed)
        .filter(|&(_, (n, _))| n as f32 > PIXEL_SHARE * shown as f32)
        .filter_map(|(rule, (n, first))| {
            let share = 100.0 * n as f32 / shown as f32;
            let text = rule.finding(&first?);
            Some(format!("with its maps, {share:.1}% of the {shown} pixels where it shows fail; the first: {text}"))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(params: &Params) -> Vec<String> {
        findings(params).into_iter().map(|(_, text)| text).collect()
    }

    #[test]
    fn each_rule_fires_and_plausible_materials_pass() {
        assert!(check(&Params::default()).is_empty());
        let gold = Params { base_color: [0.96, 0.83, 0.41], metallic: 1.0, ..Params::default() };
        assert!(check(&gold).is_empty());
        let half = Params { metallic: 0.5, ..Params::default() };
        assert!(check(&half)[0].contains("in between"));
        let snowier = Params { base_color: [0.97; 3], ..Params::default() };
        assert!(check(&snowier)[0].contains("dielectric"));
        let soot = Params { base_color: [0.01; 3], ..Params::default() };
        assert!(check(&soot)[0].contains("charcoal"));
        let dark_metal = Params { base_color: [0.2; 3], metallic: 1.0, ..Params::default() };
        assert!(check(&dark_metal)[0].contains("metal F0"));
        let gem = Params { specular: 1.5, ..Params::default() };
        assert!(check(&gem)[0].contains("specular"));
    }
}
