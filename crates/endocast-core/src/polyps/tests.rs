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

#[test]
fn finds_sessile_and_pedunculated_polyps_of_6_mm_and_more_at_their_size() {
    let (mut expected, mut hit, mut worst_size) = (0, 0, 0.0f64);
    let (mut flat, mut flat_hit) = (0, 0);
    for seed in 1..=3 {
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
            if polyp.shape == PolypShape::Flat {
                flat += 1;
                flat_hit += usize::from(matched.is_some());
                continue;
            }
            expected += 1;
            if let Some(n) = matched {
                hit += 1;
                worst_size = worst_size.max((found[*n].size_mm - polyp.diameter_vox).abs());
            }
        }
    }
    // Flat polyps are caps of little curvedness on a concave wall: reported, not required.
    eprintln!(
        "polyps of 6 mm or more found: sessile and pedunculated {hit} of {expected} (worst size \
         error {worst_size:.2} mm), flat {flat_hit} of {flat}"
    );
    assert!(
        expected >= 10,
        "only {expected} polyps of 6 mm or more drawn"
    );
    assert!(
        f64::from(hit) >= 0.9 * f64::from(expected),
        "found {hit} of {expected}"
    );
    assert!(worst_size <= 1.5, "worst size error {worst_size} mm");
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
