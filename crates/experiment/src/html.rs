//! report.html: the experiment for people to look at, in one page that needs nothing but its
//! output folder (styles and script inline, pictures as files beside it, relative links, no
//! network). It shows what report.md shows (summary, the runs, convergence rates, the
//! equal-time and equal-samples comparisons, the plots) and, per scene, an image comparison:
//! the reference, the noisy inputs, each method's final image and its error image, switched
//! by key or click and zoomed and panned together ([`crate::views`] writes the pictures).
//!
//! Every text that comes from the experiment (names, paths, messages) is escaped; the
//! templates are `html/style.css` and `html/viewer.js`.

use crate::config::Plan;
use crate::grid::{budget_label, rule_label, Results};
use crate::report::{fit_text, sci, EqualTime, RunInfo, Slopes};
use crate::views::SceneViews;
use std::fmt::Write as _;

const STYLE: &str = include_str!("html/style.css");
const SCRIPT: &str = include_str!("html/viewer.js");

/// `t` with the five characters that mean something in HTML text and attribute values
/// replaced by their entities.
pub fn escape(t: &str) -> String {
    let mut s = String::with_capacity(t.len());
    for c in t.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            c => s.push(c),
        }
    }
    s
}

/// A table cell: escaped text, right-aligned when numeric, highlighted when the best.
struct Cell {
    text: String,
    num: bool,
    best: bool,
}

fn text(t: impl Into<String>) -> Cell {
    Cell {
        text: t.into(),
        num: false,
        best: false,
    }
}

fn num(t: impl Into<String>) -> Cell {
    Cell {
        num: true,
        ..text(t)
    }
}

fn table(s: &mut String, head: &[&str], rows: &[Vec<Cell>]) {
    s.push_str("<div class=\"table-wrap\"><table>\n<thead><tr>");
    for h in head {
        let _ = write!(s, "<th>{}</th>", escape(h));
    }
    s.push_str("</tr></thead>\n<tbody>\n");
    for row in rows {
        s.push_str("<tr>");
        for c in row {
            let class = match (c.num, c.best) {
                (true, true) => " class=\"num best\"",
                (true, false) => " class=\"num\"",
                (false, true) => " class=\"best\"",
                (false, false) => "",
            };
            let _ = write!(s, "<td{class}>{}</td>", escape(&c.text));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</tbody></table></div>\n");
}

/// What [`page`] shows.
pub struct Page<'a> {
    /// The experiment.
    pub plan: &'a Plan,
    /// Its runs.
    pub results: &'a Results,
    /// Rate fits.
    pub slopes: &'a [Slopes],
    /// Equal-time comparison per scene.
    pub equal_time: &'a [EqualTime],
    /// Equal-samples comparison per scene.
    pub equal_samples: &'a [EqualTime],
    /// The comparison pictures per scene.
    pub views: &'a [SceneViews],
    /// When and how it ran.
    pub info: &'a RunInfo,
}

/// The text of report.html.
pub fn page(p: &Page<'_>) -> String {
    let plan = p.plan;
    let mut s = String::new();
    let title = format!("Experiment {}", plan.name);
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n",
        escape(&title)
    );
    let _ = writeln!(
        s,
        "<header><h1>Experiment <code>{}</code></h1>\n<p class=\"note\">Config <code>{}</code>, \
         started {} UTC, {} worker threads, {:.1} s in all. relMSE uses ε = {}. Data: \
         <a href=\"results.csv\">results.csv</a> (one row per run), \
         <a href=\"slopes.csv\">slopes.csv</a>, <a href=\"report.md\">report.md</a>; \
         EXR images in <code>images/&lt;scene&gt;/</code>.</p>",
        escape(&plan.name),
        escape(&plan.path.display().to_string()),
        escape(&p.info.started),
        p.info.threads,
        p.info.wall_seconds,
        plan.epsilon
    );
    s.push_str("<nav>Scenes: ");
    for scene in &plan.scenes {
        let _ = write!(s, "<a href=\"#scene-{0}\">{0}</a>", escape(&scene.name));
    }
    s.push_str("</nav></header>\n");
    if !plan.warnings.is_empty() {
        s.push_str("<div class=\"warnings\"><p>Warnings:</p><ul>\n");
        for w in &plan.warnings {
            let _ = writeln!(s, "<li>{}</li>", escape(w));
        }
        s.push_str("</ul></div>\n");
    }
    summary(&mut s, p);
    for (si, scene) in plan.scenes.iter().enumerate() {
        let name = escape(&scene.name);
        let _ = writeln!(
            s,
            "<section id=\"scene-{name}\">\n<h2>Scene <code>{name}</code></h2>\n\
             <p class=\"note\"><code>{}</code>, camera <code>{}</code> at {}×{}; reference: {}.</p>",
            escape(&scene.path.display().to_string()),
            escape(&scene.camera.name),
            scene.camera.width,
            scene.camera.height,
            escape(&p.results.references[si].origin)
        );
        if let Some(v) = p.views.iter().find(|v| v.scene == si) {
            viewer(&mut s, v);
        }
        let _ = writeln!(
            s,
            "<h3>Error curves</h3>\n<div class=\"plots\">\
             <img src=\"plots/{name}.svg\" alt=\"relMSE against time, {name}\">\
             <img src=\"plots/{name}-spp.svg\" alt=\"relMSE against samples per pixel, {name}\">\
             </div>"
        );
        runs(&mut s, p, si);
        rates(&mut s, p, si);
        comparison(
            &mut s,
            plan,
            &p.equal_time[si],
            "Equal time",
            "seconds",
            "relMSE of each method at the same time: render time, plus denoising time for a \
             method with a denoiser (interpolated log-log between measured points).",
        );
        comparison(
            &mut s,
            plan,
            &p.equal_samples[si],
            "Equal samples",
            "mean spp",
            "relMSE of each method at the same number of samples, counted as the mean samples \
             per pixel actually taken (interpolated log-log between measured points).",
        );
        s.push_str("</section>\n");
    }
    let _ = write!(s, "<script>\n{SCRIPT}</script>\n</body>\n</html>\n");
    s
}

fn summary(s: &mut String, p: &Page<'_>) {
    let plan = p.plan;
    s.push_str("<h2 id=\"summary\">Summary</h2>\n");
    let winner = |e: &EqualTime, what: &str| crate::report::winner(plan, e, what);
    let rows: Vec<Vec<Cell>> = plan
        .scenes
        .iter()
        .enumerate()
        .map(|(si, scene)| {
            let rates: Vec<String> = p
                .slopes
                .iter()
                .filter(|sl| sl.metric == "mse" && plan.pairs[sl.pair].scene == si)
                .map(|sl| {
                    let name = &plan.methods[plan.pairs[sl.pair].method].name;
                    format!("{name} {}", fit_text(sl.raw.0))
                })
                .collect();
            vec![
                text(scene.name.clone()),
                text(winner(&p.equal_time[si], "times")),
                text(winner(&p.equal_samples[si], "sample counts")),
                text(rates.join("; ")),
            ]
        })
        .collect();
    table(
        s,
        &[
            "scene",
            "lowest relMSE at equal time",
            "lowest relMSE at equal samples",
            "MSE slope vs spp",
        ],
        &rows,
    );
}

/// The image comparison of one scene.
fn viewer(s: &mut String, v: &SceneViews) {
    let (w, h) = v.size;
    s.push_str("<h3>Images</h3>\n");
    s.push_str(
        "<p class=\"note\">Keys <kbd>1</kbd>–<kbd>9</kbd> or <kbd>←</kbd>/<kbd>→</kbd> switch \
         pictures (in the viewer last under the mouse), the wheel or <kbd>+</kbd>/<kbd>−</kbd> \
         zooms, dragging pans, <kbd>0</kbd> or a double click fits. The view stays when the \
         picture changes, so the same pixels are compared. Error pictures: relative squared \
         error per pixel on a log scale, dark blue 1e-4 or less to yellow 10 or more.</p>\n",
    );
    let _ = writeln!(
        s,
        "<div class=\"viewer\" tabindex=\"0\" data-width=\"{w}\" data-height=\"{h}\">\n<div class=\"bar\">"
    );
    for (i, view) in v.views.iter().enumerate() {
        let key = if i < 9 {
            format!("<kbd>{}</kbd>", i + 1)
        } else {
            String::new()
        };
        let _ = write!(
            s,
            "<button type=\"button\" data-show=\"{i}\" title=\"{}\">{key}{}</button>",
            escape(&view.caption),
            escape(&view.label)
        );
    }
    s.push_str(
        "<span class=\"sep\"></span><button type=\"button\" data-zoom=\"out\" title=\"zoom out (-)\">−</button>\
         <button type=\"button\" data-zoom=\"in\" title=\"zoom in (+)\">+</button>\
         <button type=\"button\" data-zoom=\"one\" title=\"one image pixel per screen pixel\">1:1</button>\
         <button type=\"button\" data-zoom=\"fit\" title=\"fit (0)\">fit</button>\
         <span class=\"zoom-level\"></span></div>\n<div class=\"stage\"><div class=\"layer\">\n",
    );
    for view in &v.views {
        let _ = writeln!(
            s,
            "<img src=\"{}\" width=\"{w}\" height=\"{h}\" alt=\"{}\" data-caption=\"{}\" draggable=\"false\">",
            escape(&view.file),
            escape(&view.label),
            escape(&view.caption)
        );
    }
    s.push_str("</div></div>\n<div class=\"caption\"></div>\n</div>\n");
}

/// Every run on the scene, as report.md lists them.
fn runs(s: &mut String, p: &Page<'_>, si: usize) {
    let plan = p.plan;
    let denoised = plan
        .pairs
        .iter()
        .any(|q| q.scene == si && plan.methods[q.method].denoiser.is_some());
    let mut head = vec![
        "method",
        "integrator",
        "accel",
        "budget",
        "spp",
        "mean spp",
        "stop",
        "seconds",
        "Msamples/s",
        "MSE",
        "relMSE",
        "PSNR",
        "SSIM",
    ];
    if denoised {
        head.extend([
            "denoiser",
            "denoise s",
            "render + denoise s",
            "noisy relMSE",
        ]);
    }
    let mut rows = Vec::new();
    for row in p
        .results
        .rows
        .iter()
        .filter(|r| plan.pairs[r.pair].scene == si)
    {
        let pair = &plan.pairs[row.pair];
        let method = &plan.methods[pair.method];
        let (budget, stop) = match &row.stop {
            None => (
                method
                    .runs
                    .budgets()
                    .map_or(String::new(), |b| budget_label(b, row.budget)),
                "–".to_string(),
            ),
            Some(a) => (
                rule_label(&a.rule),
                format!("{}, {} blocks left", a.reason, a.blocks_left),
            ),
        };
        let m = &row.metrics;
        let mut cells = vec![
            text(method.name.clone()),
            text(pair.estimator.kind.to_string()),
            text(pair.accel.to_string()),
            text(budget),
            num(row.spp.to_string()),
            num(format!("{:.2}", row.mean_spp)),
            text(stop),
            num(format!("{:.3}", row.seconds)),
            num(format!("{:.2}", row.samples_per_second / 1e6)),
            num(sci(m.mse)),
            num(sci(m.relmse)),
            num(format!("{:.2}", m.psnr)),
            num(format!("{:.4}", m.ssim)),
        ];
        if denoised {
            cells.push(text(
                method
                    .denoiser
                    .as_ref()
                    .map_or("–".into(), |d| d.to_string()),
            ));
            match row.raw {
                Some(raw) => cells.extend([
                    num(format!("{:.3}", row.denoise_seconds)),
                    num(format!("{:.3}", row.total_seconds())),
                    num(sci(raw.relmse)),
                ]),
                None => cells.extend([num("–"), num(format!("{:.3}", row.seconds)), num("–")]),
            }
        }
        rows.push(cells);
    }
    s.push_str("<h3>Runs</h3>\n");
    if denoised {
        s.push_str(
            "<p class=\"note\">A method with a denoiser is measured by its denoised image \
             (MSE … SSIM); noisy relMSE is its rendered image before denoising. seconds is the \
             render time alone.</p>\n",
        );
    }
    table(s, &head, &rows);
}

fn rates(s: &mut String, p: &Page<'_>, si: usize) {
    let plan = p.plan;
    s.push_str(
        "<h3>Convergence rates</h3>\n<p class=\"note\">Least-squares slopes of log error against \
         log spp and log seconds (render + denoise), ± the standard error from the residuals; \
         the last column with the reference's own expected error subtracted \
         (docs/experiments.md).</p>\n",
    );
    let rows: Vec<Vec<Cell>> = p
        .slopes
        .iter()
        .filter(|sl| plan.pairs[sl.pair].scene == si)
        .map(|sl| {
            vec![
                text(plan.methods[plan.pairs[sl.pair].method].name.clone()),
                text(sl.metric),
                num(fit_text(sl.raw.0)),
                num(fit_text(sl.raw.1)),
                num(sl.subtracted.map_or("–".into(), |f| fit_text(f.0))),
            ]
        })
        .collect();
    table(
        s,
        &[
            "method",
            "metric",
            "slope vs spp",
            "slope vs seconds",
            "vs spp, reference noise subtracted",
        ],
        &rows,
    );
}

fn comparison(
    s: &mut String,
    plan: &Plan,
    e: &EqualTime,
    heading: &str,
    x_name: &str,
    explanation: &str,
) {
    let _ = writeln!(s, "<h3>{}</h3>", escape(heading));
    if e.table.is_empty() {
        let _ = writeln!(
            s,
            "<p class=\"note\">Nothing to compare: one method, or no {} value that every \
             method's curve covers.</p>",
            escape(x_name)
        );
        return;
    }
    let _ = writeln!(s, "<p class=\"note\">{}</p>", escape(explanation));
    let names: Vec<&str> = e
        .pairs
        .iter()
        .map(|&q| plan.methods[plan.pairs[q].method].name.as_str())
        .collect();
    let mut head = vec![x_name];
    head.extend(names.iter().copied());
    head.push("lowest");
    let rows: Vec<Vec<Cell>> = e
        .table
        .iter()
        .enumerate()
        .map(|(i, (t, errs))| {
            let best = e.winner(i);
            let mut cells = vec![num(format!("{t:.3}"))];
            cells.extend(errs.iter().enumerate().map(|(k, &v)| Cell {
                best: k == best && !v.is_nan(),
                ..num(sci(v))
            }));
            cells.push(text(names[best]));
            cells
        })
        .collect();
    table(s, &head, &rows);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped() {
        assert_eq!(
            escape(r#"<a href="x">Tom & 'Jerry'</a>"#),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt;"
        );
        assert_eq!(escape("plain ε"), "plain ε");
        let mut s = String::new();
        table(&mut s, &["<h>"], &[vec![text("a<b")]]);
        assert!(
            s.contains("<th>&lt;h&gt;</th>") && s.contains("<td>a&lt;b</td>"),
            "{s}"
        );
    }
}
