//! `lookdev brdf`: BRDF Explorer-style plots of materials under models, each written with the
//! CSV of the numbers it shows beside it.

use crate::lab::plot::{self, PlotFile};
use crate::lab::{furnace, luminance, Subject};
use crate::material::library::Library;
use crate::material::Params;
use crate::shading::brdf::Shading;
use crate::shading::model::Model;
use crate::{Error, Result};
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Args, Debug)]
pub struct BrdfArgs {
    #[command(subcommand)]
    pub plot: PlotKind,
}

#[derive(Subcommand, Debug)]
pub enum PlotKind {
    /// BRDF Explorer's image slice: θh across, θd down, at one φd; one panel per subject (PNG).
    Slice {
        #[command(flatten)]
        subjects: SubjectArgs,
        /// φd in degrees.
        #[arg(long = "phi-d", default_value_t = 90.0, allow_hyphen_values = true)]
        phi_d: f32,
        #[arg(long, value_name = "FILE.png")]
        out: PathBuf,
    },
    /// Directional albedo against view angle, every subject on the same axes (SVG).
    Albedo {
        #[command(flatten)]
        subjects: SubjectArgs,
        #[arg(long, value_name = "FILE.svg")]
        out: PathBuf,
    },
    /// The lobe in the plane of incidence, for light at --theta-i degrees (SVG).
    Polar {
        #[command(flatten)]
        subjects: SubjectArgs,
        #[arg(long = "theta-i", default_value_t = 45.0)]
        theta_i: f32,
        #[arg(long, value_name = "FILE.svg")]
        out: PathBuf,
    },
    /// Spheres over roughness × metallic under a uniform white environment (PNG, GPU).
    Furnace {
        /// The model (the first --model set applies; --vs is not used).
        #[command(flatten)]
        subjects: SubjectArgs,
        /// Spheres per row, roughness from 0 to 1.
        #[arg(long, default_value_t = 6)]
        columns: u32,
        /// Metallic values, one row each.
        #[arg(long, value_delimiter = ',', default_values_t = vec![0.0, 0.5, 1.0])]
        metallic: Vec<f32>,
        #[arg(long, default_value_t = 96)]
        size: u32,
        #[arg(long, default_value_t = 256)]
        spp: u32,
        #[arg(long, value_name = "NAME")]
        device: Option<String>,
        #[arg(long, value_name = "FILE.png")]
        out: PathBuf,
    },
}

/// Which materials under which models: every preset with every model.
#[derive(Args, Debug)]
pub struct SubjectArgs {
    /// A preset to plot (repeatable; default: the default material).
    #[arg(long = "preset", value_name = "NAME")]
    pub presets: Vec<String>,
    /// A parameter override on every material, as render's --set.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// The model, as render's --model (repeatable).
    #[arg(long = "model", value_name = "KEY=VALUE")]
    pub model: Vec<String>,
    /// Another model to compare, as KEY=VALUE[,KEY=VALUE...] over the --model one (repeatable).
    #[arg(long = "vs", value_name = "KEY=VALUE,...")]
    pub vs: Vec<String>,
}

impl SubjectArgs {
    fn base_model(&self) -> Result<Model> {
        let mut model = Model::default();
        for text in &self.model {
            model.set_from_text(text).map_err(Error::input)?;
        }
        Ok(model)
    }

    fn materials(&self) -> Result<Vec<(String, Params)>> {
        let library = Library::standard();
        let mut out = Vec::new();
        if self.presets.is_empty() {
            out.push(("default".to_string(), Params::default()));
        }
        for name in &self.presets {
            let preset = library.resolve(name).map_err(|e| Error::input(format!("--preset {name}: {e}")))?;
            out.push((name.clone(), preset.params));
        }
        for (_, params) in &mut out {
            for text in &self.set {
                let (param, value) = super::parse_set(text)?;
                params.set(param, value).map_err(|e| Error::input(format!("--set {text}: {e}")))?;
            }
        }
        Ok(out)
    }

    /// Every material under every model; the energy tables of models that need one are built
    /// on the GPU.
    pub fn subjects(&self, device: Option<String>) -> Result<Vec<Subject>> {
        let base = self.base_model()?;
        let mut models = vec![base];
        for text in &self.vs {
            let mut model = base;
            for part in text.split(',') {
                model.set_from_text(part).map_err(|e| Error::input(format!("--vs {text}: {e}")))?;
            }
            models.push(model);
        }
        let ctx = if models.iter().any(|m| m.energy_compensation) { Some(super::context(device)?) } else { None };
        let mut shadings = Vec::new();
        for model in &models {
            let energy = match (&ctx, model.energy_compensation) {
                (Some(ctx), true) => Some(Arc::new(crate::render::energy::build(ctx, model)?)),
                _ => None,
            };
            shadings.push(Shading::new(*model, energy));
        }
        let materials = self.materials()?;
        let mut subjects = Vec::new();
        for (name, params) in &materials {
            for shading in &shadings {
                let label = match (materials.len(), shadings.len()) {
                    (_, 1) => name.clone(),
                    (1, _) => shading.model.label(),
                    _ => format!("{name}, {}", shading.model.label()),
                };
                subjects.push(Subject { label, params: *params, shading: shading.clone() });
            }
        }
        Ok(subjects)
    }
}

fn check_extension(out: &Path, wanted: &str, flag: &str) -> Result<()> {
    match out.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case(wanted) => Ok(()),
        _ => Err(Error::input(format!("--out {}: {flag} plots are written as .{wanted}", out.display()))),
    }
}

fn drawing_failed(out: &Path, error: plot::DrawError) -> Error {
    Error::io(out, format!("drawing the plot failed: {error}"))
}

pub fn run(args: BrdfArgs) -> Result<()> {
    match args.plot {
        PlotKind::Slice { subjects, phi_d, out } => {
            check_extension(&out, "png", "slice")?;
            if !phi_d.is_finite() {
                return Err(Error::input(format!("--phi-d {phi_d}: must be a finite angle")));
            }
            let subjects = subjects.subjects(None)?;
            let mut csv = String::from("subject,theta_h,theta_d,r,g,b\n");
            let mut cells = Vec::new();
            for subject in &subjects {
                let data = plot::slice_data(subject, phi_d.to_radians());
                for (i, v) in data.iter().enumerate() {
                    csv.push_str(&format!("{},{},{},{},{},{}\n", subject.label, i % 90, i / 90, v.x, v.y, v.z));
                }
                cells.push((subject.label.clone(), plot::slice_image(&data, 2)));
            }
            let image = plot::slices_sheet(&format!("θh across, θd down, φd {phi_d}°"), cells);
            plot::write_plot(&out, PlotFile::Png(image), &csv)?;
        }
        PlotKind::Albedo { subjects, out } => {
            check_extension(&out, "svg", "albedo")?;
            let subjects = subjects.subjects(None)?;
            let angles = plot::degrees(2.0, 88.0);
            let data = plot::albedo_data(&subjects, &angles);
            let labels: Vec<String> = subjects.iter().map(|s| s.label.clone()).collect();
            let ys: Vec<Vec<f32>> = data.iter().map(|d| d.iter().map(|v| luminance(*v)).collect()).collect();
            let svg = plot::line_svg(
                "Directional albedo",
                "view angle θv (°)",
                "albedo (luminance)",
                (0.0, 90.0),
                1.0,
                &labels,
                &angles,
                &ys,
            )
            .map_err(|e| drawing_failed(&out, e))?;
            plot::write_plot(&out, PlotFile::Svg(svg), &plot::curves_csv("theta_v", &subjects, &angles, &data))?;
        }
        PlotKind::Polar { subjects, theta_i, out } => {
            check_extension(&out, "svg", "polar")?;
            if !(0.0..90.0).contains(&theta_i) {
                return Err(Error::input(format!("--theta-i {theta_i}: must be in [0, 90)")));
            }
            let subjects = subjects.subjects(None)?;
            let angles: Vec<f32> = (0..=178).map(|i| -89.0 + i as f32).collect();
            let data = plot::polar_data(&subjects, theta_i, &angles);
            let labels: Vec<String> = subjects.iter().map(|s| s.label.clone()).collect();
            let values: Vec<Vec<f32>> = data.iter().map(|d| d.iter().map(|v| luminance(*v)).collect()).collect();
            let svg = plot::polar_svg(&format!("In-plane lobe, θi = {theta_i}°"), &labels, &angles, &values, theta_i)
                .map_err(|e| drawing_failed(&out, e))?;
            plot::write_plot(&out, PlotFile::Svg(svg), &plot::curves_csv("theta_o", &subjects, &angles, &data))?;
        }
        PlotKind::Furnace { subjects, columns, metallic, size, spp, device, out } => {
            check_extension(&out, "png", "furnace")?;
            if !(2..=16).contains(&columns) {
                return Err(Error::input(format!("--columns {columns}: must be in [2, 16]")));
            }
            if metallic.is_empty() || metallic.iter().any(|m| !(0.0..=1.0).contains(m)) {
                return Err(Error::input("--metallic: values must be in [0, 1]"));
            }
            if !(16..=512).contains(&size) || spp == 0 {
                return Err(Error::input("--size must be in [16, 512] and --spp at least 1"));
            }
            let model = subjects.base_model()?;
            let (_, base) = subjects.materials()?.remove(0);
            let roughness: Vec<f32> = (0..columns).map(|i| i as f32 / (columns - 1) as f32).collect();
            let ctx = super::context(device)?;
            let grid = furnace::render(&ctx, &model, &base, &roughness, &metallic, size, spp)?;
            let mut csv = String::from(
                "roughness,metallic,rendered_r,rendered_g,rendered_b,integrated_r,integrated_g,integrated_b\n",
            );
            let mut rows = Vec::new();
            for (m, row) in metallic.iter().zip(&grid) {
                let mut cells = Vec::new();
                for cell in row {
                    let (c, e) = (cell.centre, cell.integrated);
                    csv.push_str(&format!(
                        "{},{},{},{},{},{},{},{}\n",
                        cell.params.roughness, cell.params.metallic, c.x, c.y, c.z, e.x, e.y, e.z
                    ));
                    cells.push((format!("r {:.2}", cell.params.roughness), cell.image.clone()));
                }
                rows.push((format!("metallic {m}"), cells));
            }
            let image = crate::render::sheet::rows(&rows);
            plot::write_plot(&out, PlotFile::Png(image), &csv)?;
            eprintln!("lookdev: furnace of {} ({spp} spp): {}", model.label(), plot::csv_path(&out).display());
        }
    }
    Ok(())
}
