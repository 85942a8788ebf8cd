//! Issues 17 and 31 on the shared scans: each endoscopic preset, with no point given, finds
//! the structure it means and starts inside it — the aorta (not the spine or the kidneys) on
//! the abdomen and the stent CTA, the colon (not the lung) on the abdomen, the airway tree on
//! the chest, the nasal air on CThead and the GE head (away from the scan's cut faces), the
//! lateral ventricles on the skull-stripped FLAIR, the joint space on both knees — and the
//! nasal path keeps an endoscope's clearance to the nasopharynx. Each start is checked three
//! ways: the value at the eye is on the lumen side, the eye lies in a landmark region written
//! down from the data, and most rays of a small iso render from it hit the wall at depths that
//! organ allows. Each scan is loaded once.

use endocast_core::navigate::{
    default_view, find_aorta, find_nasal_cavity, plan_in, DefaultView, DistanceField, Lumen,
    LumenChoice, LumenSide, PathEnd, FACE_MARGIN_MM, NOT_CONFIDENT, SCOPE_RADIUS_MM,
};
use endocast_core::path::SmoothOptions;
use endocast_core::pose::Pose;
use endocast_core::presets::Preset;
use endocast_core::render::{Camera, Mode, RenderSettings, Renderer};
use endocast_core::tissue::{self, ScanValues};
use endocast_core::Volume;
use endocast_io::OpenOptions;
use endocast_testdata::shared_data;
use glam::DVec3;
use std::sync::{Arc, Mutex};

/// The scan `name` under shared/data, or `None` (skipping, with a message) when absent; each
/// scan is read once for the whole binary (the abdomen serves two tests).
fn load(name: &'static str) -> Option<&'static Volume> {
    static SCANS: Mutex<Vec<(&str, Option<&Volume>)>> = Mutex::new(Vec::new());
    let mut scans = SCANS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(&(_, volume)) = scans.iter().find(|(n, _)| *n == name) {
        return volume;
    }
    let volume = shared_data(name).map(|path| {
        &*Box::leak(Box::new(
            endocast_io::open(&path, &OpenOptions::default())
                .unwrap()
                .volume,
        ))
    });
    scans.push((name, volume));
    volume
}

/// What a preset found with no point given.
struct Start {
    pose: Pose,
    threshold: f64,
    lumen: Lumen,
    end_mm: Option<DVec3>,
    what: String,
    /// Whether the value at the eye lies on the lumen side of the threshold.
    eye_in_lumen: bool,
    /// Share of the rays of a 48² iso render from the pose that hit the wall.
    hits: f64,
    /// Median depth of those hits, mm.
    median_depth_mm: f64,
}

/// The preset `name` on `volume` as `render --preset NAME` runs it with no point.
fn start(volume: &Volume, name: &str) -> Start {
    let scan = ScanValues::measure(volume);
    let resolved = tissue::resolve(Preset::find(name).unwrap(), volume, &scan);
    let choice = LumenChoice {
        preset: Some(&resolved.preset),
        within: tissue::central_structure(&resolved.preset, volume, &scan),
        ..LumenChoice::default()
    };
    let DefaultView::InsideLumen {
        pose,
        threshold,
        side,
        lumen,
        end_mm,
        what,
    } = default_view(volume, Some(&choice), 90.0)
    else {
        panic!("{name}: no structure found");
    };
    let voxel = volume
        .geometry()
        .voxel_from_world()
        .transform_point3(pose.eye_mm);
    let value = volume.sample_physical(voxel).unwrap();
    let mut settings = RenderSettings::default();
    settings.mode = Mode::Iso;
    settings.iso_hu = resolved.preset.iso;
    let renderer = Arc::new(Renderer::new(volume.clone()));
    let camera = Camera::look_at(pose.eye_mm, pose.look_at_mm, pose.up, 90.0, [48, 48]).unwrap();
    let frame = renderer.prepare(&settings).unwrap().render(&camera);
    let mut depths: Vec<f32> = frame
        .depth_mm
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .collect();
    depths.sort_by(f32::total_cmp);
    let hits = depths.len() as f64 / frame.depth_mm.len() as f64;
    let median_depth_mm = depths
        .get(depths.len() / 2)
        .map_or(f64::NAN, |&d| f64::from(d));
    eprintln!(
        "{name}: {} ({}); eye {:.1} value {value:.0}, {:.0} % hits, median depth \
         {median_depth_mm:.1} mm",
        what,
        resolved.summary,
        pose.eye_mm,
        100.0 * hits
    );
    Start {
        pose,
        threshold,
        eye_in_lumen: side.holds(value, threshold),
        lumen: *lumen,
        end_mm,
        what,
        hits,
        median_depth_mm,
    }
}

/// Most rays hit the wall, at a median depth in `depths` (mm).
fn assert_walled(name: &str, s: &Start, depths: (f64, f64)) {
    assert!(s.eye_in_lumen, "{name}: the eye is in the wall");
    assert!(
        s.hits > 0.8,
        "{name}: only {:.0} % of the rays hit",
        100.0 * s.hits
    );
    assert!(
        (depths.0..=depths.1).contains(&s.median_depth_mm),
        "{name}: median depth {} mm",
        s.median_depth_mm
    );
}

/// The index of the voxel of `volume` nearest world point `p` (mm).
fn nearest_voxel(volume: &Volume, p: DVec3) -> [usize; 3] {
    let v = volume
        .geometry()
        .voxel_from_world()
        .transform_point3(p)
        .round();
    [v.x as usize, v.y as usize, v.z as usize]
}

fn forward(pose: &Pose) -> DVec3 {
    (pose.look_at_mm - pose.eye_mm).normalize()
}

#[test]
fn angioscopy_on_the_abdomen_follows_the_aorta_from_the_top() {
    let Some(abdomen) = load("abdomen-ct-pancreas-dicom") else {
        return;
    };
    let s = start(abdomen, "angioscopy");
    assert!(s.what.starts_with("aorta"), "{}", s.what);
    assert_walled("angioscopy", &s, (5.0, 120.0));
    // Measured: the descending aorta runs down near x = 28, y = 110–135 mm from the top slice
    // (z 485) for 198 mm; bench/scenes.json's aorta scene (read by hand, z 356) lies in it.
    let landmark = DVec3::new(27.55, 113.71, 355.91);
    let voxel = abdomen
        .geometry()
        .voxel_from_world()
        .transform_point3(landmark)
        .round();
    assert!(s
        .lumen
        .contains([voxel.x as usize, voxel.y as usize, voxel.z as usize]));
    let eye = s.pose.eye_mm;
    assert!(
        (eye.x - 28.0).abs() < 15.0 && (100.0..145.0).contains(&eye.y),
        "{eye}"
    );
    assert!(eye.z > 450.0, "{eye}: not near the top");
    // Looking down the aorta, with the flow.
    assert!(forward(&s.pose).z < -0.8, "{:?}", s.pose);
    let end = s.end_mm.unwrap();
    assert!(eye.z - end.z > 150.0, "{end}");
    // The whole abdominal aorta, past the coeliac, mesenteric and renal origins, where its
    // section joins the branches' (and through the left renal artery the kidney's), down to
    // its division. Measured on the slices (3 mm apart, z = 85.91 + 3k): round from the top
    // (z 484.9, radius 13.6 mm at 130 HU) to z 286.9 (7.7–10.5 mm); the left renal artery
    // joins it to the kidney at z 280.9–283.9 (centre x 21.5, y 94.8); 6.7–7.6 mm below; a
    // figure of eight at z 190.9 and two iliac sections of 4–4.5 mm radius from z 187.9.
    let aorta = find_aorta(abdomen, 130.0, LumenSide::Above).unwrap();
    assert!(aorta.top_mm.z > 484.0, "top {}", aorta.top_mm);
    assert!(
        (190.0..200.0).contains(&aorta.bottom_mm.z),
        "bottom {}: not at the bifurcation",
        aorta.bottom_mm
    );
    let to_voxel = |p: DVec3| nearest_voxel(abdomen, p);
    let renal = DVec3::new(21.5, 94.8, 280.91);
    let kidney = DVec3::new(74.1, 122.7, 280.91);
    assert!(aorta.lumen.contains(to_voxel(renal)) && !aorta.lumen.contains(to_voxel(kidney)));
    for (c, r) in aorta.centres_mm.iter().zip(&aorta.radii_mm) {
        let plausible = if c.z > 300.0 { 8.0..15.0 } else { 5.5..11.0 };
        assert!(plausible.contains(r), "radius {r} mm at {c}");
    }
    assert!(
        (9.0..12.0).contains(&aorta.radius_mm),
        "{}",
        aorta.radius_mm
    );
}

#[test]
fn bronchoscopy_on_the_chest_starts_in_the_trachea() {
    let Some(chest) = load("chest-ct-airways-dicom") else {
        return;
    };
    let s = start(chest, "bronchoscopy");
    assert!(s.what.starts_with("airway tree"), "{}", s.what);
    assert_walled("bronchoscopy", &s, (3.0, 80.0));
    // The trachea near the carina: bench/scenes.json's trachea lies at x −10, y 66 (z 51).
    let eye = s.pose.eye_mm;
    assert!(
        (eye.truncate() - glam::DVec2::new(-12.0, 68.0)).length() < 20.0,
        "{eye}"
    );
}

#[test]
fn sinus_on_cthead_starts_in_the_nasal_cavity_not_the_mastoid_cells() {
    let Some(head) = load("head-ct-stanford-cthead/CThead.nhdr") else {
        return;
    };
    let s = start(head, "sinus");
    assert!(s.what.starts_with("nasal cavity"), "{}", s.what);
    // The passages are a few millimetres wide: the wall is near.
    assert_walled("sinus", &s, (1.0, 40.0));
    // Measured on the slices (1 × 1 × 2 mm voxels, no orientation declared: read as LPI,
    // guessed from the anatomy, k = 0 the vertex): the nasal cavity from the nostrils (j ≈ 20, k ≈ 57) back to the choanae
    // (j ≈ 100), between the hard palate (k ≈ 68) and the cribriform plate (k ≈ 38), the
    // septum at i ≈ 115; the sphenoid sinus behind it (j ≥ 95), the mastoid cells at the sides
    // (i < 70, i > 185). World mm: x = i, y = j, z = −2k.
    let eye = s.pose.eye_mm;
    assert!(
        (100.0..=135.0).contains(&eye.x)
            && (20.0..=85.0).contains(&eye.y)
            && (-136.0..=-76.0).contains(&eye.z),
        "{eye}: not in the nasal cavity"
    );
    // Looking back along the passages, towards the choanae.
    assert!(forward(&s.pose).y > 0.8, "{:?}", s.pose);
    // The largest enclosed air, which the preset took before: a left mastoid cell.
    assert!(!s.lumen.contains([160, 148, 68]));
    // Cut off from the air around the head: the mask reaches none of the volume's sides.
    let (lo, hi) = s.lumen.bounds();
    let dims = head.dims();
    assert!(
        (0..2).all(|a| lo[a] > 0 && hi[a] + 1 < dims[a]),
        "{lo:?} {hi:?}"
    );
}

#[test]
fn angioscopy_on_the_stent_cta_follows_the_stented_aorta_down_to_the_bifurcation() {
    let Some(stent) = load("aorta-stent-cta/stent.nrrd") else {
        return;
    };
    let s = start(stent, "angioscopy");
    assert!(s.what.starts_with("aorta"), "{}", s.what);
    assert_walled("angioscopy (stent)", &s, (5.0, 120.0));
    // Measured on the slices (1 mm voxels assumed, world = voxel index; k grows upwards): the
    // aorta's section centre at (73, 49) in slice 130, (74, 53) in 150, (68, 69) in 200,
    // (56, 95) at the top (255), oblique and ringed by the stent's struts; it divides into the
    // iliac arteries at k ≈ 88.
    for v in [[73, 49, 130], [74, 53, 150], [68, 69, 200]] {
        assert!(s.lumen.contains(v), "{v:?} not in the aorta");
    }
    let eye = s.pose.eye_mm;
    assert!(eye.z > 200.0, "{eye}: not near the top");
    assert!(forward(&s.pose).z < -0.6, "{:?}", s.pose);
    let end = s.end_mm.unwrap();
    assert!(
        (75.0..110.0).contains(&end.z),
        "{end}: not near the bifurcation"
    );
    let aorta = find_aorta(stent, 130.0, LumenSide::Above).unwrap();
    assert!(
        (8.0..=15.0).contains(&aorta.radius_mm),
        "radius {} mm",
        aorta.radius_mm
    );
    // A branch joins its section at k 235–237 (one region of 14–16 mm radius, roundness
    // 0.1): followed by its core through them to the top slice (it stopped at 234 before).
    assert!(aorta.top_mm.z >= 254.0, "top {}", aorta.top_mm);
    assert!(s.lumen.contains([55, 92, 236]) && s.lumen.contains([56, 95, 255]));
}

#[test]
fn colonoscopy_on_the_abdomen_starts_in_colon_gas_not_the_lung_nor_the_table() {
    let Some(abdomen) = load("abdomen-ct-pancreas-dicom") else {
        return;
    };
    let s = start(abdomen, "colonoscopy");
    assert!(s.what.starts_with("colon"), "{}", s.what);
    assert_walled("colonoscopy", &s, (2.0, 80.0));
    let to_voxel = |p: DVec3| nearest_voxel(abdomen, p);
    // Gas (below −900 HU), not aerated lung (−820 to −900).
    let [i, j, k] = to_voxel(s.pose.eye_mm);
    let value = abdomen.physical(i, j, k).unwrap();
    assert!(value < -900.0, "{value} HU at the eye");
    // Measured on the slices: the gas-filled right colon (ascending colon to the hepatic
    // flexure) lies at x −130…−60, y 0…70 mm, z 240…320 mm, below the liver; the lungs end
    // above it. A hollow in the scanner's table (x −150, y 231, z 461; 47.6 ml), which the
    // preset took before, lies outside the body.
    let eye = s.pose.eye_mm;
    assert!(
        (-140.0..=-50.0).contains(&eye.x)
            && (-10.0..=80.0).contains(&eye.y)
            && (240.0..=320.0).contains(&eye.z),
        "{eye}: not in the right colon"
    );
    assert!(!s
        .lumen
        .contains(to_voxel(DVec3::new(-152.54, 231.18, 460.91))));
}

/// The lumen's volume, ml.
fn ml(volume: &Volume, lumen: &Lumen) -> f64 {
    let s = volume.geometry().spacing_mm();
    lumen.voxel_count() as f64 * s.x * s.y * s.z / 1000.0
}

#[test]
fn ventricles_on_the_skull_stripped_flair_are_the_lateral_ventricles_not_a_pocket() {
    let Some(flair) = load("brain-mri-flair-nrrd/FLAIR.nrrd") else {
        return;
    };
    let s = start(flair, "ventricles");
    let volume_ml = ml(flair, &s.lumen);
    eprintln!(
        "ventricles on the FLAIR: {volume_ml:.1} ml at {}",
        s.threshold
    );
    // It took a 1.0 ml pocket beside them: in this skull-stripped scan the ventricles join
    // the background (0) through the CSF at the brain's surface at every threshold.
    assert!(s.what.starts_with("central CSF component"), "{}", s.what);
    assert!((7.0..=30.0).contains(&volume_ml), "{volume_ml} ml");
    assert!(s.eye_in_lumen, "the eye is in the wall");
    // Measured on the axial slices (1 mm voxels, oblique; CSF 16-47 against tissue 100-150):
    // the two lateral ventricles' bodies at i 50-56 and 62-66, j 75-105, k 80-84.
    for v in [[52, 95, 84], [54, 100, 84], [64, 95, 84]] {
        assert!(s.lumen.contains(v), "{v:?} not in the ventricles");
    }
}

#[test]
fn arthroscopy_on_both_knees_starts_in_the_joint_space_and_plans_a_path_in_it() {
    // Measured on the slices (1 x 0.97 x 1 mm, identity; k runs up the leg): the tibial
    // plateau's marrow ends and the femoral condyles' begins across a dark gap (below 30) at
    // dataT: i 60-95, k 47-53; dataR: i 75-100, k 42-50 (j 10-50 both).
    for (name, i, k) in [
        ("knee-mri/knee3D_dataT.mha", 60.0..=95.0, 44.0..=56.0),
        ("knee-mri/knee3D_dataR.mha", 75.0..=100.0, 40.0..=52.0),
    ] {
        let Some(knee) = load(name) else {
            return;
        };
        let s = start(knee, "arthroscopy");
        let v = knee
            .geometry()
            .voxel_from_world()
            .transform_point3(s.pose.eye_mm);
        eprintln!("{name}: eye voxel {v:.1}, {:.1} ml", ml(knee, &s.lumen));
        // It started in the tibial marrow, in a "lumen" of everything above 30 (126-138 ml).
        assert!(s.what.starts_with("joint space"), "{name}: {}", s.what);
        assert!(s.eye_in_lumen, "{name}: the eye is not in the dark gap");
        assert!(
            i.contains(&v.x) && k.contains(&v.z) && (10.0..=50.0).contains(&v.y),
            "{name}: eye at voxel {v}: not in the joint"
        );
        assert!(s.lumen.leak().is_none(), "{name}: the joint space leaks");
        // `path --preset arthroscopy` refused the lumen the preset found: now a path runs.
        let (_, planned) = plan_in(
            knee,
            &s.lumen,
            s.pose.eye_mm,
            PathEnd::Farthest,
            &SmoothOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        eprintln!("{name}: path {:.1} mm", planned.path.len_mm());
    }
}

#[test]
fn sinus_on_the_gantry_tilt_head_starts_away_from_the_scans_cut_faces() {
    let Some(head) = load("head-ct-ge-gantry-tilt/GE") else {
        return;
    };
    let s = start(head, "sinus");
    assert!(s.eye_in_lumen, "the eye is in the wall");
    // The camera sat 4 mm above the bottom slice: a third of the image was the cut plane.
    let v = head
        .geometry()
        .voxel_from_world()
        .transform_point3(s.pose.eye_mm);
    let dims = head.dims();
    let spacing = head.geometry().spacing_mm().to_array();
    let from_faces = (0..3)
        .map(|a| v[a].min(dims[a] as f64 - 1.0 - v[a]) * spacing[a])
        .fold(f64::INFINITY, f64::min);
    eprintln!("GE sinus: eye voxel {v:.1}, {from_faces:.1} mm from the faces");
    assert!(from_faces >= FACE_MARGIN_MM, "{from_faces} mm from a face");
    // The 28 slices run from the skull base up: the passages an endoscope would take are not
    // in the scan, and the finder says so.
    assert!(s.what.starts_with(NOT_CONFIDENT), "{}", s.what);
}

#[test]
fn the_nasal_path_on_cthead_keeps_the_scopes_clearance_and_ends_at_the_nasopharynx() {
    let Some(head) = load("head-ct-stanford-cthead/CThead.nhdr") else {
        return;
    };
    let s = start(head, "sinus");
    assert!(!s.what.starts_with(NOT_CONFIDENT), "{}", s.what);
    let end = s
        .end_mm
        .expect("the nasal cavity's path ends at the nasopharynx");
    let (_, planned) = plan_in(
        head,
        &s.lumen,
        s.pose.eye_mm,
        PathEnd::Point(end),
        &SmoothOptions::default(),
    )
    .unwrap();
    // Against the walls of all the passages, not only of the route.
    let passages = find_nasal_cavity(head, s.threshold).unwrap().passages;
    let field = DistanceField::new(&passages, head.geometry());
    let clearance = planned
        .path
        .samples()
        .iter()
        .map(|p| field.distance_mm(p.position_mm))
        .fold(f64::INFINITY, f64::min);
    let last = planned.path.samples().last().unwrap().position_mm;
    eprintln!(
        "CThead nasal path: {:.1} mm, clearance {clearance:.2} mm, from {:.1} to {last:.1}",
        planned.path.len_mm(),
        s.pose.eye_mm
    );
    // It ran 208 mm to the farthest point, a loop ending 10 mm from its start, through gaps
    // of 0.25 mm. Measured on the sagittal slices near the septum (world x = i, y = j,
    // z = 2k): the inferior meatus runs back at k 56-60 from the start (j 47) to the
    // choanae (j 95-107, k 46-66).
    assert!(clearance >= SCOPE_RADIUS_MM, "{clearance} mm from the wall");
    assert!(
        last.distance(s.pose.eye_mm) > 40.0,
        "{last}: back near the start"
    );
    assert!(last.y >= 90.0, "{last}: not at the choanae");
    assert!(
        planned.path.len_mm() < 100.0,
        "{} mm",
        planned.path.len_mm()
    );
}
