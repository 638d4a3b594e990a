//! `lookdev lint LOOK.toml`: implausible material values, each with its reason.
//!
//! Every layer's resolved parameters (its preset with its overrides) are checked. A look that
//! passes prints nothing and exits 0; findings are printed one per line, `FILE:LINE: object,
//! layer: finding`, and the exit code is 1. A look that cannot be read is an error (exit 2).

use crate::material::params::Params;
use crate::material::Look;
use crate::shading::common::luminance;
use crate::{Error, Result};
use clap::Args;
use glam::Vec3;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct LintArgs {
    pub look: PathBuf,
}

/// Plausible ranges, from measured materials: charcoal reflects about 4% and fresh snow about
/// 90%; the darkest common metal (by normal-incidence reflectance) is around 0.5 (iron,
/// titanium), so below 0.45 the base colour was probably meant for a dielectric; specular 1 is
/// F0 = 0.08, an IOR of 1.8, above nearly every common dielectric but gems.
pub const DIELECTRIC_ALBEDO: (f32, f32) = (0.02, 0.9);
pub const METAL_F0_MIN: f32 = 0.45;
pub const SPECULAR_MAX: f32 = 1.0;

/// The findings for one set of parameters.
pub fn check(params: &Params) -> Vec<String> {
    let mut findings = Vec::new();
    let m = params.metallic;
    let lum = luminance(Vec3::from(params.base_color));
    if m > 0.0 && m < 1.0 {
        findings.push(format!(
            "metallic = {m} is in between: a surface is a metal or it is not; blend a metal layer in through a mask instead"
        ));
    }
    if m < 0.5 && !(DIELECTRIC_ALBEDO.0..=DIELECTRIC_ALBEDO.1).contains(&lum) {
        findings.push(format!(
            "base_color luminance {lum:.3} is outside [{}, {}] for a dielectric: charcoal reflects about 0.04 and fresh snow about 0.9",
            DIELECTRIC_ALBEDO.0, DIELECTRIC_ALBEDO.1
        ));
    }
    if m >= 0.5 && lum < METAL_F0_MIN {
        findings.push(format!(
            "metal F0 (base_color) luminance {lum:.3} is below {METAL_F0_MIN}: darker than any common metal at normal incidence"
        ));
    }
    if params.specular > SPECULAR_MAX {
        let f0 = 0.08 * params.specular;
        let ior = (1.0 + f0.sqrt()) / (1.0 - f0.sqrt());
        findings.push(format!(
            "specular = {} is above 1: F0 {f0:.3}, an IOR of {ior:.2}, more than almost any dielectric but gems",
            params.specular
        ));
    }
    findings
}

pub fn run(args: LintArgs) -> Result<()> {
    let look = Look::load(&args.look)?;
    let mut count = 0;
    for object in &look.objects {
        let who = object.id.map(|id| format!("object {id}")).unwrap_or_else(|| "default stack".into());
        for (i, layer) in object.layers.iter().enumerate() {
            let name = layer.preset.as_deref().map(|p| format!(" ({p})")).unwrap_or_default();
            for finding in check(&layer.params) {
                println!("{}:{}: {who}, layer {i}{name}: {finding}", args.look.display(), layer.line);
                count += 1;
            }
        }
    }
    if count > 0 {
        return Err(Error::lint(format!("{}: {count} finding(s)", args.look.display())));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
