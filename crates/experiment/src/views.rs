//! The pictures of report.html's image comparison: for each scene its reference, each method's
//! final image (denoised, for a method with a denoiser), the noisy input of a denoised method,
//! and each final image's false-colour error against the reference, written as display PNGs
//! (the EXRs under `images/` stay the data).
//!
//! PNGs are what a browser shows: the linear pixels are clamped and sRGB-encoded at exposure 0
//! by [`rt_film::write_rgb`], and error images use `rt-metrics`' fixed log scale (1e-4 to 10,
//! viridis), as `render compare --error-image` does, so the error images of every method and
//! every experiment are on one scale. Files: `view/<scene>/reference.png` and
//! `view/<scene>/<method>/{final,noisy,error}.png` (a folder per method, so no method's name
//! can collide with another's picture).

use crate::config::Plan;
use crate::error::{io, ExperimentError, Result};
use crate::grid::{Results, Row};
use rt_metrics::{error_image, FalseColourOptions, RgbImage};
use std::path::Path;

/// What a picture shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewKind {
    /// The reference.
    Reference,
    /// A denoised method's image before denoising.
    Noisy,
    /// A method's final image.
    Final,
    /// The false-colour error of a method's final image.
    Error,
}

/// One picture of the comparison.
pub struct View {
    /// What it is.
    pub kind: ViewKind,
    /// Short name on its button: `reference`, `path`, `path error`, `path noisy`.
    pub label: String,
    /// One line on what it shows (budget, time, error).
    pub caption: String,
    /// The PNG, relative to the output folder, with `/` separators.
    pub file: String,
}

/// The pictures of one scene, in the order the viewer's keys select them: the reference,
/// the noisy inputs of the denoised methods, then each method's final image and its error.
pub struct SceneViews {
    /// Index into the plan's scenes.
    pub scene: usize,
    /// Image width and height in pixels.
    pub size: (usize, usize),
    /// The pictures.
    pub views: Vec<View>,
}

/// Writes the display PNGs of every scene and returns what they are.
pub fn write(plan: &Plan, results: &Results, out: &Path) -> Result<Vec<SceneViews>> {
    let colours = FalseColourOptions {
        epsilon: plan.epsilon,
        ..FalseColourOptions::default()
    };
    let mut all = Vec::new();
    for (si, scene) in plan.scenes.iter().enumerate() {
        let rel_dir = format!("view/{}", scene.name);
        let dir = out.join(&rel_dir);
        std::fs::create_dir_all(&dir).map_err(io(&dir))?;
        let reference = &results.references[si];
        // `name` is `reference` or `<method>/<picture>`.
        let png = |name: &str, img: &RgbImage| -> Result<String> {
            let file = format!("{rel_dir}/{name}.png");
            let path = out.join(&file);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(io(parent))?;
            }
            rt_film::write_rgb(&path, img, &Default::default())?;
            Ok(file)
        };
        let error = |name: &str, img: &RgbImage| -> Result<String> {
            let e = error_image(img, &reference.image, &colours)
                .map_err(|e| ExperimentError::Run(format!("{}: {name}: {e}", scene.name)))?;
            png(&format!("{name}/error"), &e)
        };
        let mut views = vec![View {
            kind: ViewKind::Reference,
            label: "reference".into(),
            caption: format!("reference: {}", reference.origin),
            file: png("reference", &reference.image)?,
        }];
        let pairs: Vec<usize> = (0..plan.pairs.len())
            .filter(|&p| plan.pairs[p].scene == si)
            .collect();
        let last = |p: usize| results.rows.iter().rev().find(|r| r.pair == p);
        for &p in &pairs {
            let name = &plan.methods[plan.pairs[p].method].name;
            if let (Some(noisy), Some(row)) = (&results.noisy_finals[p], last(p)) {
                let raw = row.raw.map_or(f64::NAN, |m| m.relmse);
                views.push(View {
                    kind: ViewKind::Noisy,
                    label: format!("{name} noisy"),
                    caption: format!(
                        "{name} before denoising: {}, relMSE {}",
                        budget_text(row),
                        crate::report::sci(raw)
                    ),
                    file: png(&format!("{name}/noisy"), noisy)?,
                });
            }
        }
        for &p in &pairs {
            let method = &plan.methods[plan.pairs[p].method];
            let name = &method.name;
            let img = &results.finals[p];
            let what = match (&method.denoiser, last(p)) {
                (Some(d), Some(r)) => format!(
                    "{name} denoised by {d}: {}, relMSE {}, {:.3} s denoising",
                    budget_text(r),
                    crate::report::sci(r.metrics.relmse),
                    r.denoise_seconds
                ),
                (None, Some(r)) => format!(
                    "{name}: {}, relMSE {}",
                    budget_text(r),
                    crate::report::sci(r.metrics.relmse)
                ),
                (_, None) => name.clone(),
            };
            views.push(View {
                kind: ViewKind::Final,
                label: name.clone(),
                caption: what.clone(),
                file: png(&format!("{name}/final"), img)?,
            });
            views.push(View {
                kind: ViewKind::Error,
                label: format!("{name} error"),
                caption: format!(
                    "relative squared error of {what} (log scale: dark blue 1e-4 or less, yellow 10 or more)"
                ),
                file: error(name, img)?,
            });
        }
        all.push(SceneViews {
            scene: si,
            size: (reference.image.width(), reference.image.height()),
            views,
        });
    }
    Ok(all)
}

/// `64 spp, 0.52 s` (mean spp for an adaptive run).
fn budget_text(r: &Row) -> String {
    if r.stop.is_some() {
        format!("{:.1} mean spp, {:.2} s", r.mean_spp, r.seconds)
    } else {
        format!("{} spp, {:.2} s", r.spp, r.seconds)
    }
}
