//! The edge-avoiding À-Trous wavelet filter of Dammertz, Sewtz, Hanika and Lensch, "Edge-Avoiding
//! À-Trous Wavelet Transform for fast Global Illumination Filtering", HPG 2010 (thesis of seed
//! 004, §6.5, Listing 6.3), with the albedo demodulation of its "deferred shading" and the
//! lighting splits of seed 002 (§3).
//!
//! Each level `i = 0..iterations−1` replaces every pixel by the mean of its 5×5 B3-spline taps
//! `2^i` pixels apart, each weighted by the kernel `h(q)` and the edge-stopping factors of the
//! shader:
//!
//! ```text
//! c_w = min(exp(−|c_p − c_q|² / c_phi), 1)                  on the level being filtered
//! n_w = min(exp(−(|n_p − n_q|² / stepwidth²) / n_phi), 1)   on the normal buffer
//! p_w = min(exp(−|x_p − x_q|² / p_phi), 1)                  on the position buffer
//! out(p) = Σ_q h(q)·c_w·n_w·p_w·c_q / Σ_q h(q)·c_w·n_w·p_w
//! ```
//!
//! The last level is the output (the detail coefficients are dropped). Levels ping-pong between
//! two buffers; rows run in parallel (same bits on any thread count); the submodules `pass`
//! (the inner loop) and `simd` (its AVX2 build) say how.
//!
//! Choices and deviations (the thesis leaves these open or is ambiguous):
//! - **Borders.** Taps outside the image read the nearest edge pixel (clamp to edge, as the
//!   GPU texture fetch of the shader). Skipping them instead would change only which weights
//!   are renormalised; a constant image stays constant either way.
//! - **c_phi.** With `scale=relative` (default) `c_phi` is a multiple of the 99th percentile of
//!   `|c|²` over the signal being filtered (per part): the thesis starts σ_rt at the buffer's
//!   maximum (HDR) intensity so that level 0 is driven by the normal and position weights; the
//!   percentile keeps a few fireflies from deciding it. The default 4 (σ twice the percentile
//!   intensity) is a compromise: of 0.25–64 on the Cornell box it was best at 4 spp (relMSE
//!   0.00161; 0.00167 at 1, 0.00172 at 64), while 1 spp wanted larger values (0.0042 at 4,
//!   0.0033 at 64, 0.016 at 1, 0.068 at 0.25).
//! - **Halving** (errata §6.2): `halve=phi` (default) divides c_phi by 2 per level,
//!   `halve=sigma` divides σ by 2 (c_phi by 4), `halve=none` keeps it. `phi` was better at
//!   1 spp (relMSE 0.0042 against 0.0046), `sigma` at 4 spp (0.0014 against 0.0016).
//! - **p_phi** is relative to the squared diagonal of the position buffer's bounding box
//!   (`scale=relative`), so the result does not change when the scene is scaled (seed 002
//!   claim 17). Default 0.001: a neighbour 3 % of the scene's extent away gets `exp(−1)`; taps
//!   16 pixels apart on a surface that spans 512 pixels and the whole extent keep
//!   `exp(−(1/32)²/0.001)` ≈ 0.38. Of 0.01, 0.001 and 0.0001 it was best at 1 spp and
//!   within 10 % of the best at 4 spp.
//! - **n_phi** default 0.01 (normals are unit vectors, no scaling). The shader divides `|Δn|²`
//!   by `stepwidth²`, so the normal weight tests the normals' gradient: a smooth curve whose
//!   normal turns by 0.1 rad per pixel keeps `exp(−1)` at every level, while a 90° crease
//!   (`|Δn|² = 2`) gets `exp(−200)` at level 0 but 0.46 at level 4. Values of 0.1–0.5 leave
//!   the crease at ≥ 0.73 from level 3 on and scored worse (relMSE 0.00186 against 0.00167 at
//!   4 spp); 0.01 and 0.001 were within 1 %.
//! - The defaults were chosen on `scenes/cornell-box.toml` (512², path tracer, `--aov
//!   denoise`, 1 and 4 spp) against 256 spp, with `examples/atrous_tune.rs`; one untextured
//!   scene, so they are a starting point rather than a fit.
//! - **One exponential.** `c_w·n_w·p_w` is computed as `exp(−(d_c + d_n + d_p))`, equal to the
//!   product of the clamped factors up to rounding since each `d ≥ 0`, with a polynomial `exp`
//!   of relative error below 4·10⁻⁷.
//! - **Demodulation** (`demodulate=auto|on|off`; auto: on when the frame has an albedo). With an
//!   `irradiance` channel the filter runs on it and the output is
//!   `albedo ⊙ F(irradiance) + (colour − albedo ⊙ irradiance)`, the second term being the
//!   emission plus a small residual, passed unfiltered. Without it the colour (minus the
//!   emission, if the frame has it) is divided by the albedo per component where the albedo
//!   exceeds 10⁻³ and multiplied back after filtering; darker components pass through.
//! - **Splits** (`split=direct-indirect|diffuse-glossy`): the two parts are filtered separately
//!   (each demodulated by division when demodulating), with their own iteration counts
//!   (seed 002: direct 3, indirect 5; diffuse 5, glossy 2), and recombined as
//!   `A' + B' + (colour − A − B)`, the last term being the emission.
//! - Non-finite input components are read as zero.

mod kernel;
mod parts;
mod pass;
mod planes;
mod simd;

use crate::{Channel, DenoiseError, Denoiser, DenoiserOptions, NoisyFrame, Options};
use parts::{colour_scale, position_scale, Part};
use pass::{Inputs, Level, Weights};
use planes::Planes;
use rt_core::{Image, Rgb, RgbImage};
use simd::Isa;

/// Most levels accepted: level 10 would space taps 1024 pixels apart.
const MAX_ITERATIONS: usize = 10;

/// How c_phi shrinks from level to level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Halve {
    /// c_phi halves per level (σ shrinks by √2).
    Phi,
    /// σ halves per level (c_phi quarters).
    Sigma,
    /// c_phi stays.
    None,
}

/// Whether to filter the illumination apart from the albedo.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Demodulate {
    /// When the frame has an albedo.
    Auto,
    /// Always (the frame must have an albedo).
    On,
    /// Never.
    Off,
}

/// Which parts of the light are filtered separately.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// The whole colour (or irradiance) at once.
    None,
    /// Direct and indirect light, with their iteration counts.
    DirectIndirect {
        /// Levels for the direct part.
        direct: usize,
        /// Levels for the indirect part.
        indirect: usize,
    },
    /// Diffuse and glossy reflection, with their iteration counts.
    DiffuseGlossy {
        /// Levels for the diffuse part.
        diffuse: usize,
        /// Levels for the glossy part.
        glossy: usize,
    },
}

/// The edge-avoiding À-Trous filter (see the module doc for the algorithm and the options).
#[derive(Clone, Debug)]
pub struct Atrous {
    iterations: usize,
    weights: Weights,
    c_phi: f32,
    n_phi: f32,
    p_phi: f32,
    relative: bool,
    halve: Halve,
    demodulate: Demodulate,
    split: Split,
    simd: bool,
    needs: Vec<Channel>,
    name: String,
}

impl Atrous {
    /// From spec options, validated (see the module doc for their meaning):
    ///
    /// | key | values | default |
    /// |---|---|---|
    /// | `iterations` | 1–10 | 5 |
    /// | `colour`, `normal`, `position` (the weights) | on, off | on |
    /// | `c_phi`, `n_phi`, `p_phi` | positive | 4, 0.01, 0.001 |
    /// | `scale` (of c_phi and p_phi) | relative, absolute | relative |
    /// | `halve` | phi, sigma, none | phi |
    /// | `demodulate` | auto, on, off | auto |
    /// | `split` | none, direct-indirect, diffuse-glossy | none |
    /// | `direct_iterations`, `indirect_iterations` (direct-indirect) | 0–10 | 3, 5 |
    /// | `diffuse_iterations`, `glossy_iterations` (diffuse-glossy) | 0–10 | 5, 2 |
    /// | `simd` (off: the portable code, for comparisons) | auto, off | auto |
    pub fn from_options(o: &mut Options) -> Result<Self, DenoiseError> {
        let iterations = o.usize("iterations", 5)?;
        if !(1..=MAX_ITERATIONS).contains(&iterations) {
            return Err(o.param_error(
                "iterations",
                format!("must be 1 to {MAX_ITERATIONS}, got {iterations}"),
            ));
        }
        let weights = Weights {
            colour: o.on_off("colour", true)?,
            normal: o.on_off("normal", true)?,
            position: o.on_off("position", true)?,
        };
        let phi = |o: &mut Options, key: &'static str, default: f32| {
            let v = o.f32(key, default)?;
            if v > 0.0 {
                Ok(v)
            } else {
                Err(o.param_error(key, format!("must be positive, got {v}")))
            }
        };
        let c_phi = phi(o, "c_phi", 4.0)?;
        let n_phi = phi(o, "n_phi", 0.01)?;
        let p_phi = phi(o, "p_phi", 0.001)?;
        let relative = o.pick("scale", &["relative", "absolute"], "relative")? == "relative";
        let halve = match o.pick("halve", &["phi", "sigma", "none"], "phi")? {
            "sigma" => Halve::Sigma,
            "none" => Halve::None,
            _ => Halve::Phi,
        };
        let demodulate = match o.pick("demodulate", &["auto", "on", "off"], "auto")? {
            "on" => Demodulate::On,
            "off" => Demodulate::Off,
            _ => Demodulate::Auto,
        };
        let part_iterations = |o: &mut Options, key: &'static str, default: usize| {
            let v = o.usize(key, default)?;
            if v > MAX_ITERATIONS {
                return Err(o.param_error(key, format!("must be 0 to {MAX_ITERATIONS}, got {v}")));
            }
            Ok(v)
        };
        let split = match o.pick(
            "split",
            &["none", "direct-indirect", "diffuse-glossy"],
            "none",
        )? {
            "direct-indirect" => Split::DirectIndirect {
                direct: part_iterations(o, "direct_iterations", 3)?,
                indirect: part_iterations(o, "indirect_iterations", 5)?,
            },
            "diffuse-glossy" => Split::DiffuseGlossy {
                diffuse: part_iterations(o, "diffuse_iterations", 5)?,
                glossy: part_iterations(o, "glossy_iterations", 2)?,
            },
            _ => Split::None,
        };
        let simd = o.pick("simd", &["auto", "off"], "auto")? == "auto";
        Ok(Self::assemble(
            iterations, weights, c_phi, n_phi, p_phi, relative, halve, demodulate, split, simd,
        ))
    }

    #[allow(clippy::too_many_arguments)]
    fn assemble(
        iterations: usize,
        weights: Weights,
        c_phi: f32,
        n_phi: f32,
        p_phi: f32,
        relative: bool,
        halve: Halve,
        demodulate: Demodulate,
        split: Split,
        simd: bool,
    ) -> Self {
        let onoff = |b: bool| if b { "on" } else { "off" };
        let mut name = format!(
            "atrous:iterations={iterations}:colour={}:normal={}:position={}:c_phi={c_phi}:n_phi={n_phi}:p_phi={p_phi}:scale={}:halve={}:demodulate={}",
            onoff(weights.colour),
            onoff(weights.normal),
            onoff(weights.position),
            if relative { "relative" } else { "absolute" },
            match halve {
                Halve::Phi => "phi",
                Halve::Sigma => "sigma",
                Halve::None => "none",
            },
            match demodulate {
                Demodulate::Auto => "auto",
                Demodulate::On => "on",
                Demodulate::Off => "off",
            },
        );
        let mut needs = Vec::new();
        if weights.normal {
            needs.push(Channel::Normal);
        }
        if weights.position {
            needs.push(Channel::Position);
        }
        if demodulate == Demodulate::On {
            // Demodulation filters reflected light: emitters seen directly (black albedo,
            // radiance far above their surroundings) are taken out first and added back, or
            // their light would be spread over the surfaces around them.
            needs.extend([Channel::Albedo, Channel::Emission]);
        }
        match split {
            Split::None => name.push_str(":split=none"),
            Split::DirectIndirect { direct, indirect } => {
                name.push_str(&format!(
                    ":split=direct-indirect:direct_iterations={direct}:indirect_iterations={indirect}"
                ));
                needs.extend([Channel::Direct, Channel::Indirect]);
            }
            Split::DiffuseGlossy { diffuse, glossy } => {
                name.push_str(&format!(
                    ":split=diffuse-glossy:diffuse_iterations={diffuse}:glossy_iterations={glossy}"
                ));
                needs.extend([Channel::Diffuse, Channel::Glossy]);
            }
        }
        if !simd {
            name.push_str(":simd=off");
        }
        Self {
            iterations,
            weights,
            c_phi,
            n_phi,
            p_phi,
            relative,
            halve,
            demodulate,
            split,
            simd,
            needs,
            name,
        }
    }

    /// The number of edge-stopping weights in use (0–3; the columns of thesis Table 6.2).
    pub fn weight_count(&self) -> usize {
        self.weights.count()
    }

    /// The parts to filter, with the albedo when demodulating.
    fn parts<'a>(&self, frame: &'a NoisyFrame) -> Vec<Part<'a>> {
        let albedo = match self.demodulate {
            Demodulate::Off => None,
            Demodulate::On | Demodulate::Auto => frame.albedo.as_ref(),
        };
        let two = |a: &Option<Image<Rgb>>, b: &Option<Image<Rgb>>, na: usize, nb: usize| {
            let (a, b) = (a.clone().unwrap_or_default(), b.clone().unwrap_or_default());
            vec![Part::new(a, albedo, na), Part::new(b, albedo, nb)]
        };
        match self.split {
            Split::DirectIndirect { direct, indirect } => {
                two(&frame.direct, &frame.indirect, direct, indirect)
            }
            Split::DiffuseGlossy { diffuse, glossy } => {
                two(&frame.diffuse, &frame.glossy, diffuse, glossy)
            }
            Split::None => match (albedo, &frame.irradiance) {
                (Some(a), Some(irr)) => vec![Part {
                    signal: irr.clone(),
                    modulation: parts::Modulation::Multiply(a),
                    iterations: self.iterations,
                }],
                (Some(_), None) => {
                    let mut c = frame.colour.clone();
                    if let Some(e) = &frame.emission {
                        for (c, e) in c.pixels_mut().iter_mut().zip(e.pixels()) {
                            *c -= *e;
                        }
                    }
                    vec![Part::new(c, albedo, self.iterations)]
                }
                (None, _) => vec![Part::new(frame.colour.clone(), None, self.iterations)],
            },
        }
    }

    /// Runs `iterations` levels on `signal`.
    fn transform(
        &self,
        signal: Planes,
        iterations: usize,
        normal: &Planes,
        position: &Planes,
    ) -> Planes {
        let isa = Isa::detect(self.simd);
        let c_scale = if self.relative && self.weights.colour {
            colour_scale(&signal)
        } else {
            1.0
        };
        let p_scale = if self.relative && self.weights.position {
            position_scale(position)
        } else {
            1.0
        };
        let shrink = match self.halve {
            Halve::Phi => 0.5,
            Halve::Sigma => 0.25,
            Halve::None => 1.0,
        };
        let mut src = signal;
        let mut dst = Planes::zeros(src.width, src.height);
        let mut c_phi = self.c_phi * c_scale;
        for level in 0..iterations {
            let step = kernel::step_width(level) as f32;
            let lv = Level {
                level,
                inv_c: 1.0 / c_phi.max(f32::MIN_POSITIVE),
                inv_n: 1.0 / (self.n_phi * step * step),
                inv_p: 1.0 / (self.p_phi * p_scale),
            };
            let inp = Inputs {
                colour: &src,
                normal,
                position,
                level: lv,
            };
            simd::pass(&inp, &mut dst, self.weights, isa);
            std::mem::swap(&mut src, &mut dst);
            c_phi *= shrink;
        }
        src
    }
}

impl Denoiser for Atrous {
    fn name(&self) -> &str {
        &self.name
    }

    fn needs(&self) -> &[Channel] {
        &self.needs
    }

    fn filter(&self, frame: &NoisyFrame) -> RgbImage {
        let (w, h) = frame.colour.size();
        let guide = |on: bool, img: &Option<Image<rt_core::glam::Vec3>>| match (on, img) {
            (true, Some(i)) => Planes::from_image(i),
            _ => Planes::zeros(0, 0),
        };
        let normal = guide(self.weights.normal, &frame.normal);
        let position = guide(self.weights.position, &frame.position);
        let parts = self.parts(frame);
        let plain = matches!(
            (&parts[..], self.split),
            ([p], Split::None) if matches!(p.modulation, parts::Modulation::None)
        );
        if plain {
            let signal = Planes::from_image(&frame.colour);
            return self
                .transform(signal, self.iterations, &normal, &position)
                .to_image();
        }
        let mut out = frame.colour.clone();
        for part in &parts {
            let signal = Planes::from_image(&part.signal);
            let filtered = self.transform(signal, part.iterations, &normal, &position);
            part.add_correction(&filtered, &mut out);
        }
        debug_assert_eq!(out.size(), (w, h));
        out
    }
}
