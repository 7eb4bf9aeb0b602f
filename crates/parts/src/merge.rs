//! Merging parts into the film of the whole render, exactly.
//!
//! Parts belong together when their headers agree on everything but the slice. Their sample
//! ranges must partition `0..spp` (a range may be split further into regions), and for each
//! range the regions must tile the image: no pixel twice, none left out. The film then adds
//! every part's exact sums; a range's light paths (which every region of it traced, keeping
//! the splats that landed inside) are counted once.

use crate::file::{Part, PartHeader};
use rt_film::{Film, FilmMemory, LateSums, Rect};
use std::collections::BTreeMap;
use std::ops::Range;

/// Why parts cannot be merged. Each message names the part files involved.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum MergeError {
    /// Nothing to merge.
    #[error("no parts to merge")]
    Empty,
    /// A part comes from another render.
    #[error("{file} does not belong with {first}: its {field} is {theirs}, not {ours}")]
    Mismatch {
        /// The part that differs.
        file: String,
        /// The part it was compared with.
        first: String,
        /// What differs.
        field: String,
        /// Its value in `file`.
        theirs: String,
        /// Its value in `first`.
        ours: String,
    },
    /// Two parts render the same samples of the same pixels.
    #[error("{a} and {b} overlap: both render {what}")]
    Overlap {
        /// One part.
        a: String,
        /// The other.
        b: String,
        /// The samples and pixels both hold.
        what: String,
    },
    /// No part renders some samples or pixels.
    #[error("a part is missing: no part renders {0}")]
    Gap(String),
    /// The merged film would not fit in the memory allowed.
    #[error("the merged film needs {need} bytes, more than the {limit} allowed")]
    Memory {
        /// Bytes the film would hold.
        need: u64,
        /// The limit.
        limit: u64,
    },
    /// A part's sums do not fit its header.
    #[error("{file}: {message}")]
    Sums {
        /// The part.
        file: String,
        /// What is wrong.
        message: String,
    },
}

/// What merging produced: the film and the slices it came from.
#[derive(Debug)]
pub struct Merged {
    /// The film of the whole render.
    pub film: Film,
    /// The header of the first part (its slice fields describe only that part).
    pub header: PartHeader,
    /// Sample ranges, in order.
    pub ranges: Vec<Range<u32>>,
}

/// The fields that must agree, as (name, value) pairs.
fn identity(h: &PartHeader) -> Vec<(String, String)> {
    let mut v = vec![
        ("format".to_string(), h.format.to_string()),
        ("binary (renderer build)".into(), h.binary.clone()),
        ("scene content (hash)".into(), h.scene_hash.clone()),
        ("frame".into(), format!("{:?}", h.frame)),
        ("image size".into(), format!("{}x{}", h.width, h.height)),
        ("spp".into(), h.spp.to_string()),
        ("AOV set".into(), h.aovs.join(",")),
        ("variance buffer".into(), h.variance.to_string()),
        ("halves buffer".into(), h.halves.to_string()),
    ];
    let keys: Vec<&String> = h.settings.keys().collect();
    v.push(("setting names".into(), format!("{keys:?}")));
    v.extend(
        h.settings
            .iter()
            .map(|(k, s)| (format!("setting {k}"), s.clone())),
    );
    v
}

/// Checks that `other` comes from the same render as `first` (everything but the slice and
/// the command line agrees), naming the first field that differs.
pub fn check_belongs(
    (first_name, first): (&str, &PartHeader),
    (name, other): (&str, &PartHeader),
) -> Result<(), MergeError> {
    let (want, got) = (identity(first), identity(other));
    match want.iter().zip(&got).find(|(a, b)| a != b) {
        Some(((field, ours), (_, theirs))) => Err(MergeError::Mismatch {
            file: name.to_string(),
            first: first_name.to_string(),
            field: field.clone(),
            theirs: theirs.clone(),
            ours: ours.clone(),
        }),
        None => Ok(()),
    }
}

fn range_text(r: &Range<u32>) -> String {
    format!("samples {}..{}", r.start, r.end)
}

/// Checks that `parts` (with their file names) make up one whole render, then adds them up.
/// `memory_limit`: the most bytes the merged film may hold (checked before allocating it).
pub fn merge(parts: &[(String, Part)], memory_limit: Option<u64>) -> Result<Merged, MergeError> {
    let (first_name, first) = parts.first().ok_or(MergeError::Empty)?;
    for (name, p) in &parts[1..] {
        check_belongs((first_name, &first.header), (name, &p.header))?;
    }
    let h = &first.header;
    let (w, hgt, spp) = (h.width, h.height, h.spp);

    // Sample ranges: each distinct one once, in order; they must partition 0..spp.
    let mut by_range: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
    for (i, (_, p)) in parts.iter().enumerate() {
        let r = p.header.sample_range();
        by_range.entry((r.start, r.end)).or_default().push(i);
    }
    let mut next = 0;
    let mut prev: Option<(u32, u32)> = None;
    for &(a, b) in by_range.keys() {
        if a > next {
            return Err(MergeError::Gap(range_text(&(next..a))));
        }
        if a < next {
            let p = prev.expect("a range before");
            return Err(MergeError::Overlap {
                a: parts[by_range[&p][0]].0.clone(),
                b: parts[by_range[&(a, b)][0]].0.clone(),
                what: range_text(&(a..next.min(b))),
            });
        }
        next = b;
        prev = Some((a, b));
    }
    if next < spp {
        return Err(MergeError::Gap(range_text(&(next..spp))));
    }
    // Within each range, the regions tile the image.
    for (&(a, b), members) in &by_range {
        for (k, &i) in members.iter().enumerate() {
            let ri = parts[i].1.header.rect();
            if let Some(&j) = members[..k]
                .iter()
                .find(|&&j| parts[j].1.header.rect().overlaps(&ri))
            {
                return Err(MergeError::Overlap {
                    a: parts[j].0.clone(),
                    b: parts[i].0.clone(),
                    what: format!(
                        "{} of pixels in both {} and {}",
                        range_text(&(a..b)),
                        parts[j].1.header.rect(),
                        ri
                    ),
                });
            }
        }
        let area: u64 = members
            .iter()
            .map(|&i| parts[i].1.header.rect().area())
            .sum();
        if area < u64::from(w) * u64::from(hgt) {
            let hole = first_uncovered(w, hgt, members.iter().map(|&i| parts[i].1.header.rect()));
            return Err(MergeError::Gap(format!(
                "{} of pixel ({}, {})",
                range_text(&(a..b)),
                hole.0,
                hole.1
            )));
        }
    }

    let buffers = h.buffers().map_err(|e| MergeError::Sums {
        file: first_name.clone(),
        message: e.to_string(),
    })?;
    // The sums a part made late (light-path splats, filtered sums) the merged film makes too.
    let late = parts.iter().fold(LateSums::default(), |l, (_, p)| {
        l | Film::encoded_late_sums(&p.sums)
    });
    let need = FilmMemory::estimate(w, hgt, buffers, 0, late).total() as u64;
    if let Some(limit) = memory_limit {
        if need > limit {
            return Err(MergeError::Memory { need, limit });
        }
    }
    let mut film = Film::new(w, hgt, buffers);
    for members in by_range.values() {
        for (k, &i) in members.iter().enumerate() {
            let (name, p) = &parts[i];
            film.add_encoded(p.header.rect(), &p.sums, k == 0)
                .map_err(|e| MergeError::Sums {
                    file: name.clone(),
                    message: e.to_string(),
                })?;
        }
    }
    Ok(Merged {
        film,
        header: first.header.clone(),
        ranges: by_range.keys().map(|&(a, b)| a..b).collect(),
    })
}

/// The first pixel (row-major) no rectangle covers; only called when the areas fall short.
fn first_uncovered(w: u32, h: u32, rects: impl Iterator<Item = Rect> + Clone) -> (u32, u32) {
    for y in 0..h {
        // The columns covered in row y, as sorted intervals.
        let mut spans: Vec<(u32, u32)> = rects
            .clone()
            .filter(|r| (r.y0..r.y1).contains(&y))
            .map(|r| (r.x0, r.x1))
            .collect();
        spans.sort_unstable();
        let mut x = 0;
        for (a, b) in spans {
            if a > x {
                return (x, y);
            }
            x = x.max(b);
        }
        if x < w {
            return (x, y);
        }
    }
    (0, 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::file::tests::header;
    use rt_core::Rgb;
    use rt_film::FirstHit;

    fn part(region: [u32; 4], samples: [u32; 2]) -> Part {
        let mut h = header();
        h.region = region;
        h.samples = samples;
        let buffers = h.buffers().unwrap();
        let mut film = Film::new(h.width, h.height, buffers);
        let r = h.rect();
        for i in samples[0]..samples[1] {
            for y in r.y0..r.y1 {
                for x in r.x0..r.x1 {
                    let v = ((x * 31 + y * 17 + i * 7) % 13) as f32 * 0.1;
                    let hit = FirstHit::default();
                    film.add_sample(x, y, i, Rgb::splat(v), Some(&hit));
                }
            }
        }
        Part {
            sums: film.encode_sums(r),
            header: h,
        }
    }

    fn named(ps: Vec<Part>) -> Vec<(String, Part)> {
        ps.into_iter()
            .enumerate()
            .map(|(i, p)| (format!("p{i}.rpart"), p))
            .collect()
    }

    #[test]
    fn splits_merge_to_the_whole() {
        let whole = merge(&named(vec![part([0, 0, 4, 3], [0, 8])]), None).unwrap();
        let split = merge(
            &named(vec![
                part([0, 0, 2, 3], [0, 3]),
                part([2, 0, 4, 3], [0, 3]),
                part([0, 0, 4, 3], [3, 8]),
            ]),
            None,
        )
        .unwrap();
        let full = Rect::full(4, 3);
        assert_eq!(split.film.encode_sums(full), whole.film.encode_sums(full));
        assert_eq!(split.ranges, vec![0..3, 3..8]);
    }

    #[test]
    fn refusals_name_the_parts() {
        let msg = |ps: Vec<Part>| merge(&named(ps), None).unwrap_err().to_string();
        let m = msg(vec![part([0, 0, 4, 3], [0, 3])]);
        assert_eq!(m, "a part is missing: no part renders samples 3..8");
        let m = msg(vec![part([0, 0, 4, 3], [0, 4]), part([0, 0, 4, 3], [3, 8])]);
        assert!(
            m.starts_with("p0.rpart and p1.rpart overlap: both render samples 3..4"),
            "{m}"
        );
        let m = msg(vec![part([0, 0, 4, 3], [0, 8]), part([1, 1, 2, 2], [0, 8])]);
        assert!(m.contains("overlap") && m.contains("1,1,2,2"), "{m}");
        let m = msg(vec![part([0, 0, 4, 2], [0, 8])]);
        assert_eq!(
            m,
            "a part is missing: no part renders samples 0..8 of pixel (0, 2)"
        );
        let m = msg(vec![part([0, 0, 4, 3], [4, 8])]);
        assert!(m.contains("samples 0..4"), "{m}");
        let mut other = part([0, 0, 4, 3], [3, 8]);
        other
            .header
            .settings
            .insert("integrator".into(), "bdpt".into());
        let m = msg(vec![part([0, 0, 4, 3], [0, 3]), other]);
        assert_eq!(
            m,
            "p1.rpart does not belong with p0.rpart: its setting integrator is bdpt, not path"
        );
        let mut other = part([0, 0, 4, 3], [3, 8]);
        other.header.scene_hash = "x".into();
        assert!(msg(vec![part([0, 0, 4, 3], [0, 3]), other]).contains("scene content"));
        let mut cut = part([0, 0, 4, 3], [0, 8]);
        cut.sums.pop();
        assert!(msg(vec![cut]).starts_with("p0.rpart: "));
        assert_eq!(msg(vec![]), "no parts to merge");
        let e = merge(&named(vec![part([0, 0, 4, 3], [0, 8])]), Some(10)).unwrap_err();
        assert!(matches!(e, MergeError::Memory { .. }));
    }
}
