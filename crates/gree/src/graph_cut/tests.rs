//! Tests of the labelling on random instances.

use super::*;
use rt_core::rng::SplitMix64;

struct Instance {
    bank: Vec<RgbImage>,
    data: Vec<Vec<f32>>,
    w: usize,
    h: usize,
}

fn instance(w: usize, h: usize, m: usize, seed: u64) -> Instance {
    let mut rng = SplitMix64::new(seed);
    let bank = (0..m)
        .map(|_| RgbImage::from_fn(w, h, |_, _| Rgb::new(rng.f32(), rng.f32(), rng.f32())))
        .collect();
    let data = (0..m)
        .map(|_| (0..w * h).map(|_| rng.f32() * 0.5).collect())
        .collect();
    Instance { bank, data, w, h }
}

fn random_labels(n: usize, m: usize, seed: u64) -> Vec<u16> {
    let mut rng = SplitMix64::new(seed);
    (0..n).map(|_| rng.below(m) as u16).collect()
}

/// 4-connected components of equal labels.
fn components(labels: &[u16], w: usize, h: usize) -> usize {
    let mut seen = vec![false; labels.len()];
    let mut count = 0;
    let mut stack = Vec::new();
    for s in 0..labels.len() {
        if seen[s] {
            continue;
        }
        count += 1;
        seen[s] = true;
        stack.push(s);
        while let Some(p) = stack.pop() {
            let (x, y) = (p % w, p / w);
            let mut visit = |q: usize| {
                if !seen[q] && labels[q] == labels[p] {
                    seen[q] = true;
                    stack.push(q);
                }
            };
            if x > 0 {
                visit(p - 1);
            }
            if x + 1 < w {
                visit(p + 1);
            }
            if y > 0 {
                visit(p - w);
            }
            if y + 1 < h {
                visit(p + w);
            }
        }
    }
    count
}

#[test]
fn energy_never_rises_and_is_reported_truthfully() {
    for seed in 0..8u64 {
        let inst = instance(23, 17, 2 + seed as usize % 4, seed);
        // From data-dominated (0, 0.01) to seam-dominated (3): a wrong data or a wrong seam
        // term in the expansion graph shows up at one end or the other.
        let pw = [0.0, 0.01, 0.3, 3.0][seed as usize % 4];
        let problem = LabelProblem::with_scales(&inst.bank, &inst.data, 1.0, pw);
        // Odd seeds restrict the later sweeps to a band around the boundaries.
        let options = CutOptions {
            band: (seed % 2 == 1).then_some(1),
            ..CutOptions::default()
        };
        for init in [
            problem.argmin(),
            random_labels(inst.w * inst.h, inst.bank.len(), seed + 100),
        ] {
            let e0 = problem.energy(&init);
            let out = alpha_expansion(&problem, init, &options);
            assert_eq!(out.initial_energy, e0);
            assert!(out.energy <= e0, "seed {seed}: {} > {e0}", out.energy);
            assert_eq!(out.energy, problem.energy(&out.labels));
        }
    }
}

/// After α-expansion has converged, no single pixel can change label and lower the energy
/// (a one-pixel relabelling is an expansion move, and each expansion is an exact min cut).
/// With a band of 0 (only boundary pixels may switch in later sweeps) this holds only
/// thanks to the unrestricted sweep that must confirm convergence.
#[test]
fn converged_labelling_is_a_local_minimum() {
    for seed in 0..8u64 {
        let inst = instance(12, 9, 3 + seed as usize % 2, 40 + seed % 4);
        let problem = LabelProblem::with_scales(&inst.bank, &inst.data, 1.0, 0.2);
        let out = alpha_expansion(
            &problem,
            problem.argmin(),
            &CutOptions {
                max_sweeps: 50,
                tolerance: 0.0,
                band: (seed >= 4).then_some(0),
            },
        );
        assert!(out.sweeps < 50, "did not converge");
        let mut labels = out.labels.clone();
        for p in 0..labels.len() {
            let keep = labels[p];
            for l in 0..inst.bank.len() as u16 {
                labels[p] = l;
                let e = problem.energy(&labels);
                assert!(
                    e >= out.energy - 1e-9 * out.energy.abs(),
                    "seed {seed} p {p} l {l}: {e} < {}",
                    out.energy
                );
            }
            labels[p] = keep;
        }
    }
}

#[test]
fn zero_lambda_gives_the_argmin() {
    for seed in 0..4u64 {
        let inst = instance(19, 13, 4, 70 + seed);
        let problem = LabelProblem::with_scales(&inst.bank, &inst.data, 1.0, 0.0);
        let start = random_labels(inst.w * inst.h, 4, seed);
        let out = alpha_expansion(&problem, start, &CutOptions::default());
        assert_eq!(out.labels, problem.argmin());
    }
}

#[test]
fn large_lambda_merges_label_regions() {
    for seed in 0..4u64 {
        let inst = instance(32, 24, 4, 90 + seed);
        let argmin = LabelProblem::with_scales(&inst.bank, &inst.data, 1.0, 0.0).argmin();
        let before = components(&argmin, inst.w, inst.h);
        let problem = LabelProblem::with_scales(&inst.bank, &inst.data, 1.0, 1.0);
        let out = alpha_expansion(&problem, argmin, &CutOptions::default());
        let after = components(&out.labels, inst.w, inst.h);
        assert!(
            after * 4 < before,
            "seed {seed}: {after} vs {before} components"
        );
    }
}

/// λ and the data term are normalised by the mean bank radiance: scaling every radiance by 4
/// (errors by 16) gives the same labels.
#[test]
fn labelling_is_scale_free() {
    let inst = instance(24, 16, 3, 7);
    let scaled: Vec<RgbImage> = inst
        .bank
        .iter()
        .map(|f| RgbImage::from_fn(inst.w, inst.h, |x, y| f.pixel(x, y) * 4.0))
        .collect();
    let data16: Vec<Vec<f32>> = inst
        .data
        .iter()
        .map(|d| d.iter().map(|v| v * 16.0).collect())
        .collect();
    let a = LabelProblem::new(&inst.bank, &inst.data, 0.3, ErrorMetric::Squared);
    let b = LabelProblem::new(&scaled, &data16, 0.3, ErrorMetric::Squared);
    let la = alpha_expansion(&a, a.argmin(), &CutOptions::default());
    let lb = alpha_expansion(&b, b.argmin(), &CutOptions::default());
    assert_eq!(la.labels, lb.labels);
    assert!(la.accepted > 0);
}

#[test]
fn seam_cost_is_symmetric_and_zero_on_equal_labels() {
    let inst = instance(5, 4, 3, 1);
    let problem = LabelProblem::with_scales(&inst.bank, &inst.data, 1.0, 1.0);
    for p in 0..19 {
        let q = p + 1;
        assert_eq!(problem.seam_cost(p, q, 1, 1), 0.0);
        let ab = problem.seam_cost(p, q, 0, 2);
        assert!(ab > 0.0);
        assert!((ab - problem.seam_cost(p, q, 2, 0)).abs() < 1e-12);
        // Triangle inequality (a metric in the labels).
        assert!(ab <= problem.seam_cost(p, q, 0, 1) + problem.seam_cost(p, q, 1, 2) + 1e-9);
    }
}

/// The energy of the best α-expansion move from `labels`, by trying every subset of the
/// pixels not labelled α.
fn best_move(problem: &LabelProblem, labels: &[u16], alpha: u16) -> f64 {
    let n = labels.len();
    let mut best = f64::INFINITY;
    let mut moved = labels.to_vec();
    for mask in 0u32..(1 << n) {
        for p in 0..n {
            moved[p] = if mask >> p & 1 == 1 { alpha } else { labels[p] };
        }
        best = best.min(problem.energy(&moved));
    }
    best
}

/// Each expansion is the optimal α-move, and the energy change it reports is the true one,
/// also when it starts from the flow of α's previous expansion (the labels change in
/// between: every proposal is taken, better or not, and two pixels are relabelled at random
/// so the labelling keeps its boundaries). Small λ, so data and seams both matter.
#[test]
fn expansion_is_the_best_move_and_reports_its_energy_change() {
    let mut rng = SplitMix64::new(5);
    for seed in 0..12u64 {
        let (w, h, m) = if seed % 2 == 0 { (3, 3, 3) } else { (4, 2, 3) };
        let inst = instance(w, h, m, 200 + seed);
        let pw = [0.01, 0.03, 0.1][seed as usize % 3];
        let problem = LabelProblem::with_scales(&inst.bank, &inst.data, 1.0, pw);
        let mut labels = random_labels(w * h, m, seed);
        let mut buf = Buffers {
            warm: vec![Vec::new(); m],
            ..Buffers::default()
        };
        for step in 0..3 * m {
            let alpha = (step % m) as u16;
            let before = problem.energy(&labels);
            let best = best_move(&problem, &labels, alpha);
            match expand(&problem, &labels, alpha, false, &mut buf) {
                None => assert!(
                    best >= before - 1e-12,
                    "seed {seed} step {step}: missed a move"
                ),
                Some(delta) => {
                    let after = problem.energy(&buf.proposal);
                    assert!(
                        (after - best).abs() < 1e-9,
                        "seed {seed} step {step}: {after} vs best {best}"
                    );
                    assert!(
                        (before + delta - after).abs() < 1e-9,
                        "seed {seed} step {step}: change {delta} vs {}",
                        after - before
                    );
                    labels.clone_from(&buf.proposal);
                }
            }
            for _ in 0..2 {
                labels[rng.below(w * h)] = rng.below(m) as u16;
            }
        }
    }
}
