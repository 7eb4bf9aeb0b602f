//! Plans: a render cut into parts that any scheduler can run, one index each.
//!
//! `render plan` writes one; `render part plan.json --index I -o DIR` renders part `I` into
//! `DIR`; `render merge --plan plan.json DIR` writes every output from its parts. An engine's
//! adapter is then a loop or an array over `0..parts.len()` and one merge (tools/slurm,
//! tools/kubernetes).

use serde::{Deserialize, Serialize};

/// Version of the plan format (2: renders are typed jobs, not command lines).
pub const PLAN_FORMAT: u32 = 2;

/// One render of a plan: what its parts run.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedRender {
    /// The render job, as JSON with its own format version (`rt_session`'s
    /// `RenderJob::to_json`); each part sets its own frame, slice and output.
    pub job: serde_json::Value,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
}

/// One part of a plan.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedPart {
    /// Its index (the scheduler's task index).
    pub index: usize,
    /// Which render of the plan it belongs to.
    pub render: usize,
    /// Frame of a sequence, if any.
    pub frame: Option<u32>,
    /// Pixels `[x0, y0, x1, y1]`.
    pub region: [u32; 4],
    /// Sample indices `[start, end]`.
    pub samples: [u32; 2],
    /// File name of the part, inside the parts directory.
    pub file: String,
}

/// One output: the parts that merge into it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedOutput {
    /// Which render of the plan.
    pub render: usize,
    /// Frame of a sequence, if any.
    pub frame: Option<u32>,
    /// Indices of its parts.
    pub parts: Vec<usize>,
    /// The image to write; for a reference (`into_cache`), the reference cache directory.
    pub output: String,
    /// True if the merge stores a reference in the cache that experiments read.
    #[serde(default)]
    pub into_cache: bool,
}

/// A render cut into parts.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// [`PLAN_FORMAT`].
    pub format: u32,
    /// The renders cut (one for an image or a sequence; one per reference of an experiment).
    pub renders: Vec<PlannedRender>,
    /// Every part, in index order.
    pub parts: Vec<PlannedPart>,
    /// Every output and its parts.
    pub outputs: Vec<PlannedOutput>,
}

/// How to cut a render.
#[derive(Clone, Debug)]
pub struct PlanRequest {
    /// The render.
    pub render: PlannedRender,
    /// True if its outputs go into the reference cache (`frames`' paths name the cache).
    pub into_cache: bool,
    /// Frames, each with its output path; `None` for a still.
    pub frames: Vec<(Option<u32>, String)>,
    /// Tile size in pixels (`--tiles WxH`); `None`: the whole image.
    pub tile: Option<(u32, u32)>,
    /// Number of sample ranges (`--sample-splits K`).
    pub sample_splits: u32,
}

/// Why a plan cannot be made or read.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// A request that cannot be cut.
    #[error("{0}")]
    Request(String),
    /// A plan file that does not hold together.
    #[error("bad plan: {0}")]
    Invalid(String),
}

/// Most parts a plan may hold.
pub const MAX_PARTS: usize = 1 << 20;

impl Plan {
    /// Cuts renders: every frame of each into tiles (row-major; the last column and row take
    /// what is left) times sample ranges (as equal as integers allow).
    pub fn new(requests: &[PlanRequest]) -> Result<Plan, PlanError> {
        let mut plan = Plan {
            format: PLAN_FORMAT,
            renders: Vec::new(),
            parts: Vec::new(),
            outputs: Vec::new(),
        };
        for r in requests {
            plan.add(r)?;
        }
        Ok(plan)
    }

    fn add(&mut self, r: &PlanRequest) -> Result<(), PlanError> {
        let bad = |m: String| Err(PlanError::Request(m));
        let render = self.renders.len();
        let (width, height, spp) = (r.render.width, r.render.height, r.render.spp);
        if r.sample_splits == 0 || r.sample_splits > spp {
            return bad(format!(
                "--sample-splits {} must be between 1 and the {spp} spp",
                r.sample_splits
            ));
        }
        let (tw, th) = r.tile.unwrap_or((width, height));
        if tw == 0 || th == 0 {
            return bad("--tiles: a tile must be at least 1x1 pixels".into());
        }
        let cols = width.div_ceil(tw);
        let rows = height.div_ceil(th);
        let count = cols as u64 * rows as u64 * u64::from(r.sample_splits) * r.frames.len() as u64
            + self.parts.len() as u64;
        if count > MAX_PARTS as u64 {
            return bad(format!(
                "{count} parts is more than the {MAX_PARTS} a plan may hold"
            ));
        }
        for (frame, output) in &r.frames {
            let mut mine = Vec::new();
            for k in 0..r.sample_splits {
                let s =
                    |k: u32| (u64::from(k) * u64::from(spp) / u64::from(r.sample_splits)) as u32;
                for ty in 0..rows {
                    for tx in 0..cols {
                        let index = self.parts.len();
                        let region = [
                            tx * tw,
                            ty * th,
                            ((tx + 1) * tw).min(width),
                            ((ty + 1) * th).min(height),
                        ];
                        self.parts.push(PlannedPart {
                            index,
                            render,
                            frame: *frame,
                            region,
                            samples: [s(k), s(k + 1)],
                            file: format!("part-{index:06}.rpart"),
                        });
                        mine.push(index);
                    }
                }
            }
            self.outputs.push(PlannedOutput {
                render,
                frame: *frame,
                parts: mine,
                output: output.clone(),
                into_cache: r.into_cache,
            });
        }
        self.renders.push(r.render.clone());
        Ok(())
    }

    /// Parses and checks a plan file's text.
    pub fn from_json(text: &str) -> Result<Plan, PlanError> {
        let p: Plan = serde_json::from_str(text).map_err(|e| PlanError::Invalid(e.to_string()))?;
        if p.format != PLAN_FORMAT {
            return Err(PlanError::Invalid(format!(
                "format {} (this renderer reads {PLAN_FORMAT})",
                p.format
            )));
        }
        if p.renders.iter().any(|r| !r.job.is_object()) {
            return Err(PlanError::Invalid("a render without a job".into()));
        }
        if p.parts.len() > MAX_PARTS {
            return Err(PlanError::Invalid(format!("{} parts", p.parts.len())));
        }
        for (i, part) in p.parts.iter().enumerate() {
            let ok_name = !part.file.is_empty()
                && !part.file.contains(['/', '\\'])
                && part.file != ".."
                && part.file != ".";
            if part.index != i || !ok_name || part.render >= p.renders.len() {
                return Err(PlanError::Invalid(format!(
                    "part {i} is out of order or has a bad file name"
                )));
            }
        }
        if p.outputs
            .iter()
            .flat_map(|o| &o.parts)
            .any(|&i| i >= p.parts.len())
        {
            return Err(PlanError::Invalid(
                "an output names a part the plan does not have".into(),
            ));
        }
        Ok(p)
    }

    /// The plan as JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a plan serializes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(tile: Option<(u32, u32)>, splits: u32, frames: usize) -> PlanRequest {
        PlanRequest {
            render: PlannedRender {
                job: serde_json::json!({"format": 1, "job": {"scene": "scene.toml"}}),
                width: 10,
                height: 7,
                spp: 9,
            },
            into_cache: false,
            frames: (0..frames)
                .map(|f| (Some(f as u32), format!("f{f}.exr")))
                .collect(),
            tile,
            sample_splits: splits,
        }
    }

    #[test]
    fn tiles_and_ranges_cover_each_frame_once() {
        let p = Plan::new(&[request(Some((4, 4)), 2, 3)]).unwrap();
        // 3 columns x 2 rows x 2 ranges per frame.
        assert_eq!(p.parts.len(), 3 * 12);
        assert_eq!(p.outputs.len(), 3);
        for o in &p.outputs {
            assert_eq!(o.parts.len(), 12);
            let mut cover = vec![0u32; 70];
            for &i in &o.parts {
                let part = &p.parts[i];
                assert_eq!(part.frame, o.frame);
                let [x0, y0, x1, y1] = part.region;
                for y in y0..y1 {
                    for x in x0..x1 {
                        cover[(y * 10 + x) as usize] += part.samples[1] - part.samples[0];
                    }
                }
            }
            assert!(cover.iter().all(|&c| c == 9), "{cover:?}");
        }
        let back = Plan::from_json(&p.to_json()).unwrap();
        assert_eq!(back, p);
        assert!(Plan::new(&[request(None, 10, 1)]).is_err());
        assert!(Plan::new(&[request(None, 0, 1)]).is_err());
        assert!(Plan::new(&[request(Some((0, 2)), 1, 1)]).is_err());
        // Two renders: parts numbered on, each pointing at its render.
        let two = Plan::new(&[request(None, 3, 1), request(Some((5, 7)), 1, 1)]).unwrap();
        assert_eq!(two.parts.len(), 5);
        assert_eq!(two.parts[4].render, 1);
        assert_eq!(two.outputs[1].parts, vec![3, 4]);
        assert_eq!(Plan::from_json(&two.to_json()).unwrap(), two);
        let mut evil = p.clone();
        evil.parts[3].file = "../x".into();
        assert!(Plan::from_json(&evil.to_json()).is_err());
        let mut evil = p;
        evil.outputs[0].parts.push(999);
        assert!(Plan::from_json(&evil.to_json()).is_err());
    }
}
