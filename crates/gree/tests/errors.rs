//! Typed errors: bad parameters and inputs, and a misbehaving renderer.

mod common;

use common::truth;
use rt_gree::{composite, CacheRenderer, GreeError, GreeParams, Rgb, RgbImage};

#[derive(Debug, thiserror::Error)]
#[error("out of samples")]
struct OutOfSamples;

/// Fails, or returns one value too few, or a NaN.
enum Bad {
    Fails,
    Short,
    Nan,
}

impl CacheRenderer for Bad {
    type Error = OutOfSamples;
    fn render_caches(
        &mut self,
        pixels: &[(u32, u32)],
        _spp: u32,
    ) -> Result<Vec<Rgb>, OutOfSamples> {
        match self {
            Bad::Fails => Err(OutOfSamples),
            Bad::Short => Ok(vec![Rgb::ZERO; pixels.len() - 1]),
            Bad::Nan => Ok(vec![Rgb::splat(f32::NAN); pixels.len()]),
        }
    }
}

fn inputs() -> (RgbImage, RgbImage, Vec<RgbImage>) {
    let t = truth(32, 24);
    let var = RgbImage::from_fn(32, 24, |_, _| Rgb::splat(0.01));
    (t.clone(), var, vec![t])
}

#[test]
fn renderer_failures_are_typed() {
    let (n, v, bank) = inputs();
    let p = GreeParams::default();
    let err = composite(&n, &v, &bank, &mut Bad::Fails, &p).unwrap_err();
    assert!(matches!(err, GreeError::Renderer(OutOfSamples)));
    assert!(std::error::Error::source(&err).is_some());
    assert!(matches!(
        composite(&n, &v, &bank, &mut Bad::Short, &p),
        Err(GreeError::CacheCount { .. })
    ));
    assert!(matches!(
        composite(&n, &v, &bank, &mut Bad::Nan, &p),
        Err(GreeError::NonFiniteCache { .. })
    ));
}

#[test]
fn bad_inputs_are_typed() {
    let (n, v, bank) = inputs();
    let p = GreeParams::default();
    let r = &mut Bad::Fails; // never reached
    assert!(matches!(
        composite(&n, &v, &[], r, &p),
        Err(GreeError::EmptyBank)
    ));
    let small = RgbImage::from_fn(31, 24, |_, _| Rgb::ZERO);
    match composite(&n, &v, &[bank[0].clone(), small], r, &p) {
        Err(GreeError::SizeMismatch { what, .. }) => assert_eq!(what, "bank[1]"),
        other => panic!("{other:?}"),
    }
    let neg = RgbImage::from_fn(32, 24, |x, y| {
        Rgb::splat(if (x, y) == (3, 4) { -1.0 } else { 0.0 })
    });
    assert!(matches!(
        composite(&n, &neg, &bank, r, &p),
        Err(GreeError::NegativeVariance { x: 3, y: 4 })
    ));
    let nan = RgbImage::from_fn(32, 24, |x, _| {
        Rgb::splat(if x == 5 { f32::NAN } else { 0.0 })
    });
    assert!(matches!(
        composite(&n, &v, &[nan], r, &p),
        Err(GreeError::NonFinite { x: 5, y: 0, .. })
    ));
    let bad = GreeParams {
        kappa: 1.5,
        ..GreeParams::default()
    };
    assert!(matches!(
        composite(&n, &v, &bank, r, &bad),
        Err(GreeError::InvalidParam { name: "kappa", .. })
    ));
    let empty = RgbImage::from_fn(0, 0, |_, _| Rgb::ZERO);
    assert!(matches!(
        composite(&empty, &empty, std::slice::from_ref(&empty), r, &p),
        Err(GreeError::EmptyImage { .. })
    ));
}
