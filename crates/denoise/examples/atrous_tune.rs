//! Scores denoiser specs on a saved noisy frame against a reference: MSE, relMSE and SSIM per
//! spec, the input first. Used to choose the À-Trous defaults on a rendered frame.
//!
//! `cargo run --release -p rt-denoise --example atrous_tune -- NOISY.exr REFERENCE.exr SPEC...`
//! (NOISY written with `render --aov denoise`, REFERENCE any EXR with R, G, B).

use rt_denoise::{DenoiserSpec, NoisyFrame};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [noisy, reference, specs @ ..] = &args[..] else {
        return Err("usage: atrous_tune NOISY.exr REFERENCE.exr SPEC...".into());
    };
    let frame = NoisyFrame::from_exr(Path::new(noisy))?;
    let reference = NoisyFrame::from_exr(Path::new(reference))?.colour;
    let score = |name: &str, img: &rt_core::RgbImage| -> Result<(), Box<dyn std::error::Error>> {
        let mse = rt_metrics::mse(img, &reference)?;
        let rel = rt_metrics::relmse(img, &reference, 1e-2)?;
        let ssim = rt_metrics::ssim(img, &reference)?;
        println!("{mse:>10.6} {rel:>10.6} {ssim:>7.4}  {name}");
        Ok(())
    };
    println!("{:>10} {:>10} {:>7}  spec", "mse", "relmse", "ssim");
    score("input", &frame.colour)?;
    for s in specs {
        let d = s.parse::<DenoiserSpec>()?.build()?;
        score(s, &d.denoise(&frame)?)?;
    }
    Ok(())
}
