//! What a sequence experiment leaves behind: frames.csv (one row per frame of every method on
//! every scene), sequences.csv (one row per method and scene: the temporal metrics), a plot
//! per scene of relMSE over frames, report.md and a plain report.html listing the same tables,
//! plots and stills (first, middle and last frames).

use crate::config::{Plan, Runs};
use crate::error::Result;
use crate::html::escape;
use crate::plot::{self, Chart, Series};
use crate::report::{sci, RunInfo};
use crate::sequence::{SequenceResults, SequenceRow, LAG_FACTOR, LAG_WINDOW};
use std::fmt::Write as _;
use std::path::Path;

/// The columns of frames.csv.
pub const FRAMES_HEADER: &str = "scene,method,frame,relmse,mse,ssim,render_s,guides_s,denoise_s";

/// The columns of sequences.csv.
pub const SEQUENCES_HEADER: &str = "scene,method,frames,temporal_error,\
reference_temporal_error,temporal_relmse,lag,mean_relmse,last_relmse,ms_per_frame,\
temporal_error_specular";

fn names(plan: &Plan, pair: usize) -> (&str, &str) {
    let p = &plan.pairs[pair];
    (&plan.scenes[p.scene].name, &plan.methods[p.method].name)
}

/// frames.csv.
pub fn frames_csv(plan: &Plan, results: &SequenceResults) -> String {
    let mut s = format!("{FRAMES_HEADER}\n");
    for r in &results.frames {
        let (scene, method) = names(plan, r.pair);
        let _ = writeln!(
            s,
            "{scene},{method},{},{},{},{},{},{},{}",
            r.frame,
            r.metrics.relmse,
            r.metrics.mse,
            r.metrics.ssim,
            r.times.render.as_secs_f64(),
            r.times.guides.as_secs_f64(),
            r.times.denoise.as_secs_f64()
        );
    }
    s
}

/// sequences.csv; `lag` is empty without an event or when the error never recovers.
pub fn sequences_csv(plan: &Plan, results: &SequenceResults) -> String {
    let mut s = format!("{SEQUENCES_HEADER}\n");
    for r in &results.sequences {
        let (scene, method) = names(plan, r.pair);
        let _ = writeln!(
            s,
            "{scene},{method},{},{},{},{},{},{},{},{},{}",
            r.frames,
            r.temporal_error,
            r.reference_temporal_error,
            r.temporal_relmse,
            r.lag.map(|l| l.to_string()).unwrap_or_default(),
            r.mean_relmse,
            r.last_relmse,
            r.ms_per_frame,
            r.temporal_error_specular
                .map(|v| v.to_string())
                .unwrap_or_default()
        );
    }
    s
}

/// `plots/<scene>-frames.png` and `.svg`: relMSE over frames, one line per method.
pub fn plots(plan: &Plan, results: &SequenceResults, out: &Path) -> Result<()> {
    let dir = out.join("plots");
    std::fs::create_dir_all(&dir).map_err(crate::error::io(&dir))?;
    for (si, scene) in plan.scenes.iter().enumerate() {
        let series: Vec<Series> = plan
            .pairs
            .iter()
            .enumerate()
            .filter(|(_, p)| p.scene == si)
            .map(|(pi, p)| Series {
                name: plan.methods[p.method].name.clone(),
                points: results
                    .frames_of(pi)
                    .map(|r| (f64::from(r.frame), r.metrics.relmse))
                    .collect(),
            })
            .collect();
        let title = format!("{}: relMSE per frame", scene.name);
        plot::write_linear_x(
            &Chart {
                title: &title,
                x_label: "frame",
                y_label: "relMSE",
                x_base: 10.0,
                series: &series,
            },
            &dir.join(format!("{}-frames.png", scene.name)),
            &dir.join(format!("{}-frames.svg", scene.name)),
        )?;
    }
    Ok(())
}

/// A method's description for the tables: its spp and denoiser.
fn method_text(plan: &Plan, pair: usize) -> String {
    let m = &plan.methods[plan.pairs[pair].method];
    let spp = match m.runs {
        Runs::Sequence { spp } => spp,
        _ => 0,
    };
    match &m.temporal {
        Some(t) => format!("{spp} spp, {t}"),
        None => format!("{spp} spp"),
    }
}

fn lag_text(r: &SequenceRow, has_event: bool) -> String {
    match (has_event, r.lag) {
        (false, _) => "–".into(),
        (true, Some(l)) => l.to_string(),
        (true, None) => "never".into(),
    }
}

/// The per-scene table rows: cells of every method of scene `si`.
fn table(
    plan: &Plan,
    results: &SequenceResults,
    si: usize,
) -> (Vec<&'static str>, Vec<Vec<String>>) {
    let has_event = plan.scenes[si]
        .sequence
        .as_ref()
        .is_some_and(|s| s.event.is_some());
    let head = vec![
        "method",
        "settings",
        "temporal error",
        "over specular pixels",
        "reference's",
        "temporal relMSE",
        "lag (frames)",
        "mean relMSE",
        "last-frame relMSE",
        "ms per frame",
    ];
    let rows = results
        .sequences
        .iter()
        .filter(|r| plan.pairs[r.pair].scene == si)
        .map(|r| {
            vec![
                plan.methods[plan.pairs[r.pair].method].name.clone(),
                method_text(plan, r.pair),
                sci(r.temporal_error),
                r.temporal_error_specular.map_or("–".into(), sci),
                sci(r.reference_temporal_error),
                sci(r.temporal_relmse),
                lag_text(r, has_event),
                sci(r.mean_relmse),
                sci(r.last_relmse),
                format!("{:.1}", r.ms_per_frame),
            ]
        })
        .collect();
    (head, rows)
}

/// One line on a scene's frames: range, rate, camera, event.
fn scene_line(plan: &Plan, results: &SequenceResults, si: usize) -> String {
    let scene = &plan.scenes[si];
    let Some(seq) = &scene.sequence else {
        return String::new();
    };
    let mut s = format!(
        "Frames {}..{} at {} fps, {}x{}, camera `{}`",
        seq.frames.start,
        seq.frames.end,
        seq.fps,
        scene.camera.width,
        scene.camera.height,
        scene.camera.name
    );
    if let Some(e) = seq.event {
        let _ = write!(
            s,
            "; event at frame {e}: the lag counts frames from it until the relMSE is within {LAG_FACTOR}x the median of the {} frames before",
            ((e - seq.frames.start) as usize).min(LAG_WINDOW)
        );
    }
    let _ = write!(s, ". References: {}.", results.reference_origins[si]);
    s
}

/// report.md of a sequence experiment.
pub fn markdown(plan: &Plan, results: &SequenceResults, info: &RunInfo) -> String {
    let mut s = info.header(
        plan,
        " (sequences)",
        "Data: [frames.csv](frames.csv) (one row per frame), [sequences.csv](sequences.csv) \
         (one row per method and scene); stills in `images/<scene>/`.\n\n\
         Temporal error: mean absolute luminance change between consecutive frames (the \
         reference's column is what the scene itself changes). Temporal relMSE: relMSE of each \
         frame difference against the reference's difference, averaged over the steps.\n",
    );
    for (si, scene) in plan.scenes.iter().enumerate() {
        let _ = writeln!(s, "## {}\n", scene.name);
        let _ = writeln!(s, "{}\n", scene_line(plan, results, si));
        let (head, rows) = table(plan, results, si);
        let _ = writeln!(s, "| {} |", head.join(" | "));
        let _ = writeln!(s, "|{}", "---|".repeat(head.len()));
        for r in rows {
            let _ = writeln!(s, "| {} |", r.join(" | "));
        }
        let _ = writeln!(
            s,
            "\n![relMSE per frame](plots/{0}-frames.png)\n\n### Frames\n",
            scene.name
        );
        let stills: Vec<_> = results.stills.iter().filter(|t| t.scene == si).collect();
        let mut frames: Vec<u32> = stills.iter().map(|t| t.frame).collect();
        frames.sort_unstable();
        frames.dedup();
        let _ = writeln!(
            s,
            "| | {} |",
            frames
                .iter()
                .map(|f| format!("frame {f}"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        let _ = writeln!(s, "|---|{}", "---|".repeat(frames.len()));
        let mut methods: Vec<&str> = Vec::new();
        for t in &stills {
            if !methods.contains(&t.method.as_str()) {
                methods.push(&t.method);
            }
        }
        for m in methods {
            let cells: Vec<String> = frames
                .iter()
                .map(|&f| {
                    stills
                        .iter()
                        .find(|t| t.method == m && t.frame == f)
                        .map_or("–".into(), |t| format!("![{m} {f}]({})", t.file))
                })
                .collect();
            let _ = writeln!(s, "| {m} | {} |", cells.join(" | "));
        }
        s.push('\n');
    }
    s
}

/// report.html of a sequence experiment: the tables, the plots and the stills, plain (no
/// viewer yet).
pub fn html(plan: &Plan, results: &SequenceResults, info: &RunInfo) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{0}</title>\
         <style>body{{font-family:sans-serif;margin:1.5em;}}table{{border-collapse:collapse;margin:0.5em 0;}}\
         td,th{{border:1px solid #ccc;padding:0.2em 0.5em;text-align:right;}}\
         td:first-child,th:first-child{{text-align:left;}}img.still{{image-rendering:pixelated;width:256px;}}\
         figure{{display:inline-block;margin:0.3em;}}</style></head><body>\n\
         <h1>Experiment <code>{0}</code> (sequences)</h1>\n<p>Started {1} UTC, {2} worker threads, \
         {3:.1} s in all; relMSE ε = {4}. Data: <a href=\"frames.csv\">frames.csv</a>, \
         <a href=\"sequences.csv\">sequences.csv</a>, <a href=\"report.md\">report.md</a>.</p>\n",
        escape(&plan.name),
        escape(&info.started),
        info.threads,
        info.wall_seconds,
        plan.epsilon
    );
    for (si, scene) in plan.scenes.iter().enumerate() {
        let name = escape(&scene.name);
        let _ = writeln!(
            s,
            "<h2>{name}</h2>\n<p>{}</p>",
            escape(&scene_line(plan, results, si))
        );
        let (head, rows) = table(plan, results, si);
        s.push_str("<table><tr>");
        for h in head {
            let _ = write!(s, "<th>{}</th>", escape(h));
        }
        s.push_str("</tr>\n");
        for r in rows {
            s.push_str("<tr>");
            for c in r {
                let _ = write!(s, "<td>{}</td>", escape(&c));
            }
            s.push_str("</tr>\n");
        }
        s.push_str("</table>\n");
        let _ = writeln!(
            s,
            "<p><img src=\"plots/{name}-frames.svg\" alt=\"relMSE per frame of {name}\"></p>"
        );
        for t in results.stills.iter().filter(|t| t.scene == si) {
            let label = format!("{} frame {}", t.method, t.frame);
            let _ = writeln!(
                s,
                "<figure><img class=\"still\" src=\"{}\" alt=\"{1}\"><figcaption>{1}</figcaption></figure>",
                escape(&t.file),
                escape(&label)
            );
        }
    }
    s.push_str("</body></html>\n");
    s
}
