use super::*;
use crate::navigate::{Lumen, LumenSide};
use crate::phantom::{colon_polyps, PhantomOptions, PolypColon, PolypShape};

/// The colon phantom of `size` with `count` polyps drawn with `seed`, its lumen and truth.
fn phantom(size: usize, count: usize, seed: u64) -> (Volume, Lumen, PolypColon) {
    let options = PhantomOptions {
        size,
        seed,
        polyps: Some(count),
        ..Default::default()
    };
    let (volume, truth) = colon_polyps(&options, count);
    let start = truth
        .colon
        .centreline
        .point_at(truth.colon.centreline.length_vox() / 2.0);
    let seed_voxel = start.round().to_array().map(|c| c as usize);
    let lumen = Lumen::from_seed(&volume, seed_voxel, -480.0, LumenSide::Below).unwrap();
    (volume, lumen, truth)
}

/// Size and where the tests draw their phantoms: the lumen 7.5–12.5 mm in radius, its folds
/// every 22 mm.
const SIZE: usize = 320;

/// A polyp counts as found by a candidate whose tip lies within its radius and this of its
/// own, mm.
const FOUND_WITHIN_MM: f64 = 2.0;

/// How the candidates of one phantom match its polyps: per polyp, the index of the nearest
/// candidate near its tip; and the candidates that match none.
fn matches(
    volume: &Volume,
    truth: &PolypColon,
    found: &[Candidate],
) -> (Vec<Option<usize>>, usize) {
    let geometry = volume.geometry();
    let per_polyp: Vec<Option<usize>> = truth
        .polyps
        .iter()
        .map(|p| {
            let tip = geometry.world_of(p.tip_vox());
            let near = |c: &&Candidate| {
                c.centre_mm.distance(tip) <= p.diameter_vox / 2.0 + FOUND_WITHIN_MM
            };
            found
                .iter()
                .filter(near)
                .min_by(|a, b| {
                    a.centre_mm
                        .distance(tip)
                        .total_cmp(&b.centre_mm.distance(tip))
                })
                .and_then(|c| found.iter().position(|f| std::ptr::eq(f, c)))
        })
        .collect();
    let false_positives = (0..found.len())
        .filter(|n| !per_polyp.contains(&Some(*n)))
        .count();
    (per_polyp, false_positives)
}

/// Per shape: polyps of 6 mm or more drawn, found, and the worst and summed size errors of those
/// found (mm).
#[derive(Default, Debug)]
struct Tally {
    drawn: usize,
    found: usize,
    worst_size_mm: f64,
    total_size_mm: f64,
}

#[test]
fn finds_polyps_of_6_mm_and_more_of_every_shape_at_their_size() {
    let mut tally: [Tally; 3] = Default::default();
    for seed in 1..=6 {
        let (volume, lumen, truth) = phantom(SIZE, 9, seed);
        assert_eq!(truth.polyps.len(), 9, "seed {seed}");
        let found = find_candidates(&volume, &lumen, &PolypOptions::default()).unwrap();
        let (per_polyp, false_positives) = matches(&volume, &truth, &found);
        assert!(
            false_positives <= 5,
            "seed {seed}: {false_positives} false positives"
        );
        for (polyp, matched) in truth.polyps.iter().zip(&per_polyp) {
            if polyp.diameter_vox < 6.0 {
                continue;
            }
            let shape = PolypShape::ALL
                .iter()
                .position(|s| *s == polyp.shape)
                .unwrap();
            let t = &mut tally[shape];
            t.drawn += 1;
            if let Some(n) = matched {
                t.found += 1;
                let error = (found[*n].size_mm - polyp.diameter_vox).abs();
                t.worst_size_mm = t.worst_size_mm.max(error);
                t.total_size_mm += error;
            }
        }
    }
    eprintln!("polyps of 6 mm or more (sessile, pedunculated, flat): {tally:?}");
    let drawn: usize = tally.iter().map(|t| t.drawn).sum();
    let hit: usize = tally.iter().map(|t| t.found).sum();
    assert!(drawn >= 25, "only {drawn} polyps of 6 mm or more drawn");
    assert!(tally.iter().all(|t| t.drawn >= 5), "{tally:?}");
    assert!(hit as f64 >= 0.9 * drawn as f64, "found {hit} of {drawn}");
    // The issue asks sizes within 1.5 mm: the largest diameter of the base (of the head for a
    // pedunculated polyp), what the phantom draws and a radiologist measures. Measured (six
    // seeds, mean / worst): sessile 0.41 / 0.98 mm, pedunculated 0.18 / 0.22, flat 0.31 / 1.20.
    for t in &tally {
        assert!(t.worst_size_mm <= 1.5, "{tally:?}");
    }
}

#[test]
fn a_colon_of_folds_only_gives_at_most_three_candidates() {
    let (volume, lumen, truth) = phantom(SIZE, 0, 4);
    assert!(truth.polyps.is_empty());
    let found = find_candidates(&volume, &lumen, &PolypOptions::default()).unwrap();
    assert!(found.len() <= 3, "{found:?}");
}

#[test]
fn bad_options_are_named_and_the_grid_checked() {
    let (volume, lumen, _) = phantom(64, 0, 1);
    let nan = PolypOptions {
        sigma_mm: f64::NAN,
        ..PolypOptions::default()
    };
    let error = find_candidates(&volume, &lumen, &nan).unwrap_err();
    assert!(error.to_string().contains("sigma_mm"), "{error}");
    let hysteresis = PolypOptions {
        grow_shape_index: 0.95,
        ..PolypOptions::default()
    };
    assert!(hysteresis
        .check()
        .unwrap_err()
        .to_string()
        .contains("grow_shape_index"));
    let (other, _, _) = phantom(72, 0, 1);
    assert!(matches!(
        find_candidates(&other, &lumen, &PolypOptions::default()),
        Err(PolypError::OtherGrid { .. })
    ));
}
