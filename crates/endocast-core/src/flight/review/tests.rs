use super::*;
use crate::camera::Optics;
use crate::path::SmoothOptions;
use crate::phantom::{Phantom, PhantomOptions};
use crate::presets::Preset;
use crate::study::{Study, StudyRequest, LOOK_AHEAD_MM};

/// The colon phantom at `size`, its lumen, its automatic path and a renderer.
fn colon(size: usize) -> (Arc<Renderer>, Lumen, Route, RenderSettings) {
    let volume = Phantom::Colon.build(&PhantomOptions {
        size,
        ..Default::default()
    });
    let request = StudyRequest::preset(Preset::find("colonoscopy").unwrap());
    let study = Study::resolve(&volume, &request);
    let planned = study
        .plan(&volume, None, None, &SmoothOptions::default())
        .unwrap();
    let lumen = study.structure().unwrap().clone();
    let settings = study.settings().clone();
    let renderer = Arc::new(Renderer::for_many_frames(volume));
    (renderer, lumen, Route::Path(planned.planned.path), settings)
}

/// A one-way 90° pinhole flight of `size²` frames every 2 mm, reviewing every patch.
fn forward_review(settings: RenderSettings, size: usize) -> ReviewRequest {
    ReviewRequest {
        settings,
        look: None,
        flight: FlightOptions {
            size: [size, size],
            optics: Optics::default(),
            stereo: None,
            layout: Layout::Endoscope,
            window: Window::AIR_TISSUE,
        },
        step_mm: 2.0,
        look_ahead_mm: LOOK_AHEAD_MM,
        both_ways: false,
        min_area_mm2: 0.0,
    }
}

#[test]
fn a_forward_flight_plus_the_review_of_its_patches_sees_the_colon_wall() {
    let (renderer, lumen, route, settings) = colon(96);
    let request = forward_review(settings, 96);
    let mut shown = 0;
    let on_view = |_: usize, _: &PatchView, image: &Image| {
        shown += usize::from(image.rgb().iter().any(|&c| c > 0));
        Ok::<_, FlightError>(())
    };
    let review = review(&renderer, &lumen, &route, &request, || {}, on_view).unwrap();
    let before = review.before().seen_fraction();
    let after = review.after.seen_fraction();
    eprintln!(
        "{} patches, {} views: {:.1} % → {:.1} %",
        review.patches_total,
        review.views.len(),
        100.0 * before,
        100.0 * after
    );
    assert!(before < 0.97, "a forward flight misses wall: {before}");
    assert!(after >= 0.98, "before {before}, after {after}");
    // The coverage grows with each patch visited, ending at the review's.
    assert_eq!(review.after_each.len(), review.views.len());
    assert!(review.after_each.windows(2).all(|w| w[0] <= w[1]));
    assert_eq!(review.after_each.last(), Some(&after));
    assert_eq!(shown, review.views.len());
    // Every patch is seen by its own view, from an eye with a clear line of sight.
    for (view, seen) in review.views.iter().zip(&review.seen_by_view) {
        assert!(view.clear, "{view:?}");
        assert!(
            *seen > 0,
            "patch at {:?} unseen by its view",
            view.patch.centroid_mm
        );
        assert!((MIN_FOV_DEG..=MAX_FOV_DEG).contains(&view.fov_deg));
    }
}
