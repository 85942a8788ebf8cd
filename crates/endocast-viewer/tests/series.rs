//! A DICOM folder holding several series: the largest opens, the others are listed, and the
//! one chosen opens instead (real scans: a few slices of two CT series in one folder).

use crate::harness::{options, run_until};
use endocast_testdata::shared_data;
use endocast_viewer::app::ViewerApp;
use endocast_viewer::scene::ScanSource;

/// A folder with slices 20–23 of the chest CT and 1–3 of the abdomen CT.
fn two_series(dir: &std::path::Path) -> Option<()> {
    let chest = shared_data("chest-ct-airways-dicom")?;
    let abdomen = shared_data("abdomen-ct-pancreas-dicom")?;
    for n in 20..24 {
        let name = format!("00-slice{n:03}.dcm");
        std::fs::copy(chest.join(&name), dir.join(format!("chest-{name}"))).unwrap();
    }
    for n in 1..4 {
        let name = format!("1-{n:03}.dcm");
        std::fs::copy(abdomen.join(&name), dir.join(format!("abdomen-{name}"))).unwrap();
    }
    Some(())
}

#[test]
fn a_folder_of_two_series_opens_the_largest_and_then_the_one_chosen() {
    let dir = tempfile::tempdir().unwrap();
    if two_series(dir.path()).is_none() {
        return;
    }
    let ctx = egui::Context::default();
    let source = ScanSource::File {
        path: dir.path().to_owned(),
        series: None,
        orientation: None,
    };
    let mut app = ViewerApp::new(ctx.clone(), options(source));
    run_until(&ctx, &mut app, |a| a.session().is_some());
    let scene = std::sync::Arc::clone(app.session().unwrap().scene());
    assert_eq!(scene.series_found.len(), 2, "{:?}", scene.series_found);
    assert_eq!(scene.volume().dims()[2], 4);
    let other = scene.series_found[1].clone();
    assert_eq!(other.images, 3);
    // Choosing the other series reads it; the open one stays usable meanwhile.
    let chosen = ScanSource::File {
        path: dir.path().to_owned(),
        series: Some(other.uid.clone()),
        orientation: None,
    };
    app.start_loading(chosen, None);
    assert!(app.is_loading() && app.session().is_some());
    run_until(&ctx, &mut app, |a| !a.is_loading());
    let scene = app.session().unwrap().scene();
    assert_eq!(scene.volume().dims()[2], 3, "{}", app.message());
    assert_eq!(scene.series_found.len(), 2);
    // A series that is not there: said, and the scan open stays.
    let missing = ScanSource::File {
        path: dir.path().to_owned(),
        series: Some("1.2.3.nothing".into()),
        orientation: None,
    };
    app.start_loading(missing, None);
    run_until(&ctx, &mut app, |a| !a.is_loading());
    assert!(app.message().contains("1.2.3.nothing"), "{}", app.message());
    assert_eq!(app.session().unwrap().scene().volume().dims()[2], 3);
}
