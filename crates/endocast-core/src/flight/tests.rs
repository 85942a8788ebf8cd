use super::*;
use crate::animation::KeyFrame;
use crate::coverage::Coverage;
use crate::navigate::{Lumen, LumenSide};
use crate::phantom::{self, PhantomOptions};
use crate::render::{Mode, RenderSettings, Renderer};
use crate::views::slices::Window;
use std::sync::Arc;

fn straight(len: f64) -> Route {
    let points = [DVec3::ZERO, DVec3::new(0.0, 0.0, len)];
    Route::Path(Path::from_points_exact(&points, 0.5).unwrap())
}

#[test]
fn shots_cover_the_route_at_the_step_and_look_ahead() {
    let shots = straight(10.0).shots(2.5, 4.0).unwrap();
    assert_eq!(shots.len(), 5);
    for (n, shot) in shots.iter().enumerate() {
        assert!((shot.arc_mm - 2.5 * n as f64).abs() < 1e-9);
        assert!((shot.pose.eye_mm.z - shot.arc_mm).abs() < 0.02);
        assert!(shot.pose.look_at_mm.z > shot.pose.eye_mm.z || n == 4);
    }
    let back = straight(10.0).reversed(0.5).unwrap().unwrap();
    let first = &back.shots(2.5, 4.0).unwrap()[0];
    assert!((first.pose.eye_mm.z - 10.0).abs() < 0.02 && first.pose.look_at_mm.z < 10.0);
    assert!(straight(10.0).shots(f64::NAN, 1.0).is_err());
    assert!(straight(10.0).shots(1e-9, 1.0).is_err());
}

#[test]
fn key_frame_shots_carry_their_render_parameters() {
    let key = |z: f64, iso: f64| {
        KeyFrame::new(DVec3::new(0.0, 0.0, z), DVec3::Z, DVec3::Y, 60.0, iso, 0.5).unwrap()
    };
    let route = Route::Keys(Animation::new(vec![key(0.0, -500.0), key(10.0, -300.0)]).unwrap());
    let shots = route.shots(5.0, 10.0).unwrap();
    assert_eq!(shots.len(), 3);
    let look = shots[1].look.as_ref().unwrap();
    assert!((look.iso_hu + 400.0).abs() < 1e-6);
    assert_eq!(shots[1].fov_deg, Some(60.0));
    assert!(route.reversed(0.5).is_none());
}

#[test]
fn a_dashboard_frame_is_wider_than_the_view_and_coverage_grows() {
    let options = PhantomOptions {
        size: 40,
        ..Default::default()
    };
    let (volume, _) = phantom::straight_tube(&options);
    let lumen = Lumen::from_seed(&volume, [20, 20, 20], -480.0, LumenSide::Below).unwrap();
    let geometry = *volume.geometry();
    let renderer = Arc::new(Renderer::new(volume));
    let route = straight(15.0);
    let flight_options = FlightOptions {
        size: [48, 48],
        fov_deg: 90.0,
        layout: Layout::Dashboard,
        window: Window::AIR_TISSUE,
    };
    let flight = Flight::new(renderer, flight_options);
    let overview = lumen_overview(&lumen, &geometry, flight.overview_size().unwrap()).unwrap();
    let (lo, hi) = lumen.bounds();
    let bbox = [0, 1, 2].map(|a| lo[a].saturating_sub(1)..(hi[a] + 2).min(geometry.dims()[a]));
    let coverage = Coverage::new(&geometry, |v| lumen.is_wall(v), &bbox).unwrap();
    let mut flight = flight
        .with_overview(overview, route.points_mm(1.0).unwrap())
        .unwrap()
        .with_coverage(coverage);
    let settings = RenderSettings {
        mode: Mode::Iso,
        iso_hu: -480.0,
        ..RenderSettings::default()
    };
    let mut seen = Vec::new();
    for (n, shot) in route.shots(5.0, 5.0).unwrap().iter().enumerate() {
        let (image, stats) = flight.frame(n, shot, &settings).unwrap();
        assert!(image.width() > 2 * 48 && image.height() >= 48);
        assert_eq!(stats.rays, 48 * 48);
        seen.push(flight.coverage().unwrap().seen_count());
    }
    assert!(seen.windows(2).all(|w| w[1] >= w[0]) && seen[seen.len() - 1] > seen[0]);
}
