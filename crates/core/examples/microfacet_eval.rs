//! Evaluates microfacet BSDFs (`rt_core::microfacet`) for cases read from standard input, one
//! per line, and prints `f·|cos θi|` (red channel) and the pdf: the quantities Mitsuba's
//! `BSDF.eval` and `BSDF.pdf` return, for `tools/reference/compare_microfacet.py`.
//!
//! A line: `conductor|dielectric|plastic beckmann|ggx|smooth αx αy η κ wo.x wo.y wo.z wi.x wi.y wi.z`
//! (η is interior over exterior for dielectrics and plastic; κ is plastic's diffuse
//! reflectance and ignored for dielectrics).
//!
//!     echo "conductor ggx 0.3 0.3 0.2 3.9 0 0.6 0.8 0.3 0 0.95" | cargo run -p rt-core --example microfacet_eval

use rt_core::glam::Vec3;
use rt_core::microfacet::{
    Distribution, DistributionKind, LocalBsdf, Microfacet, Plastic, RoughConductor,
    RoughDielectric, RoughPlastic,
};
use rt_core::Rgb;
use std::io::BufRead;

fn main() {
    // Rough plastic tabulates at construction: build it once per parameter set.
    let mut cached: Option<(String, Microfacet)> = None;
    for line in std::io::stdin().lock().lines() {
        let line = line.expect("standard input");
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() != 12 {
            eprintln!("expected 12 fields, got {}: {line}", w.len());
            std::process::exit(2);
        }
        let x: Vec<f32> = w[2..]
            .iter()
            .map(|s| s.parse().expect("a number"))
            .collect();
        let distribution = match w[1] {
            "ggx" => Some(Distribution::new(DistributionKind::Ggx, x[0], x[1])),
            "beckmann" => Some(Distribution::new(DistributionKind::Beckmann, x[0], x[1])),
            _ => None,
        };
        let key = w[..6].join(" ");
        let bsdf = match w[0] {
            "roughplastic" => match &cached {
                Some((k, b)) if *k == key => *b,
                _ => {
                    let b = Microfacet::RoughPlastic(RoughPlastic::new(
                        distribution.expect("a distribution"),
                        Rgb::splat(x[3]),
                        Rgb::ONE,
                        x[2],
                        false,
                    ));
                    cached = Some((key, b));
                    b
                }
            },
            "conductor" => Microfacet::Conductor(RoughConductor {
                distribution,
                eta: Rgb::splat(x[2]),
                k: Rgb::splat(x[3]),
                specular_reflectance: Rgb::ONE,
                two_sided: false,
            }),
            "plastic" => Microfacet::Plastic(Plastic {
                diffuse: Rgb::splat(x[3]),
                specular: Rgb::ONE,
                eta: x[2],
                nonlinear: false,
                two_sided: false,
            }),
            _ => Microfacet::Dielectric(RoughDielectric {
                distribution,
                eta: x[2],
                reflectance: Rgb::ONE,
                transmittance: Rgb::ONE,
            }),
        };
        let wo = Vec3::new(x[4], x[5], x[6]).normalize();
        let wi = Vec3::new(x[7], x[8], x[9]).normalize();
        let (f, pdf) = bsdf.eval_pdf(wo, wi);
        println!("{} {}", f.x * wi.z.abs(), pdf);
    }
}
