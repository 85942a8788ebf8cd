use super::*;
use crate::animation::KeyFrame;
use crate::camera::Optics;
use crate::coverage::Coverage;
use crate::navigate::{Lumen, LumenSide};
use crate::phantom::{self, PhantomOptions};
use crate::render::{Mode, RenderSettings, Renderer, TransferFunction};
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
        optics: Optics::default(),
        stereo: None,
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

#[test]
fn routes_through_points_or_key_frames_and_spread_poses() {
    let points = [
        DVec3::ZERO,
        DVec3::new(0.0, 0.0, 5.0),
        DVec3::new(0.0, 0.0, 12.0),
    ];
    let route = Route::through_points(&points).unwrap();
    assert!((route.len_mm() - 12.0).abs() < 0.05);
    assert!(Route::through_points(&points[..1]).is_err());
    let poses = route.spread_poses(4, 10.0).unwrap();
    assert_eq!(poses.len(), 4);
    assert!(poses[0].eye_mm.z.abs() < 0.02);
    assert!((poses[3].eye_mm.z - 12.0).abs() < 0.05);
    assert!((poses[1].eye_mm.z - 4.0).abs() < 0.05);
    assert!(Route::from_key_frames(Vec::new()).is_err());
    let key = KeyFrame::new(DVec3::ZERO, DVec3::Z, DVec3::Y, 60.0, -500.0, 1.0).unwrap();
    assert!(matches!(
        Route::from_key_frames(vec![key]).unwrap(),
        Route::Keys(_)
    ));
}

#[test]
fn shot_settings_take_a_key_frames_look_and_load_each_transfer_function_once() {
    let base = RenderSettings::default();
    let mut loads = Vec::new();
    let mut settings = ShotSettings::new(base.clone(), |name: &str| {
        loads.push(name.to_owned());
        TransferFunction::preset(name).ok_or(format!("no preset {name}"))
    });
    let plain = straight(4.0).shots(2.0, 1.0).unwrap();
    assert_eq!(settings.for_shot(&plain[0]).unwrap(), base);
    let mut shot = plain[0].clone();
    shot.look = Some(ShotLook {
        iso_hu: -321.0,
        iso_opacity: 0.25,
        tf: Some("ramp".into()),
    });
    for _ in 0..3 {
        let s = settings.for_shot(&shot).unwrap();
        assert_eq!((s.iso_hu, s.iso_opacity), (-321.0, 0.25));
        assert_eq!(s.tf, TransferFunction::preset("ramp").unwrap());
        assert_eq!(s.mode, base.mode);
    }
    shot.look = Some(ShotLook {
        tf: None,
        ..shot.look.clone().unwrap()
    });
    assert_eq!(settings.for_shot(&shot).unwrap().tf, base.tf);
    shot.look = Some(ShotLook {
        tf: Some("no such tf".into()),
        ..shot.look.clone().unwrap()
    });
    assert!(settings.for_shot(&shot).is_err());
    drop(settings);
    assert_eq!(loads, ["ramp", "no such tf"]);
}

#[test]
fn flying_back_sees_at_least_the_forward_wall_and_the_figures_add_up() {
    let (volume, _) = phantom::straight_tube(&PhantomOptions {
        size: 40,
        ..Default::default()
    });
    let lumen = Lumen::from_seed(&volume, [20, 20, 20], -480.0, LumenSide::Below).unwrap();
    let geometry = *volume.geometry();
    let renderer = Arc::new(Renderer::new(volume));
    let options = FlightOptions {
        size: [32, 32],
        optics: Optics::default(),
        stereo: None,
        layout: Layout::Endoscope,
        window: Window::AIR_TISSUE,
    };
    let settings = RenderSettings {
        mode: Mode::Iso,
        iso_hu: -480.0,
        ..RenderSettings::default()
    };
    let route = straight(15.0);
    let wall = wall_coverage(&lumen, &geometry).unwrap();
    let mut flight = Flight::new(renderer.clone(), options.clone()).with_coverage(wall.clone());
    let shots = route.shots(5.0, 5.0).unwrap();
    for (n, shot) in shots.iter().enumerate() {
        flight.frame(n, shot, &settings).unwrap();
    }
    let forward = flight.into_coverage().unwrap();
    let back = BackwardPass::new(renderer.clone(), &route, &options, 5.0, 5.0, &forward)
        .unwrap()
        .unwrap();
    assert_eq!(back.shots().len(), shots.len());
    assert!(back.shots()[0].pose.eye_mm.z > back.shots()[1].pose.eye_mm.z);
    let mut frames = 0;
    let backward = back.fly(&settings, || frames += 1).unwrap();
    assert_eq!(frames, shots.len());
    let seen = WallSeen::with_backward(forward.clone(), &backward).unwrap();
    assert_eq!(seen.wall_voxels(), wall.total());
    assert_eq!(backward.total(), wall.total());
    assert_eq!(seen.seen_forward(), forward.seen_count());
    assert!(seen.seen_forward_backward() >= seen.seen_forward().max(backward.seen_count()));
    assert!(seen.fraction_forward_backward() > seen.fraction_forward());
    let mask = seen.mask_volume().unwrap();
    assert_eq!(mask.voxels().len(), geometry.dims().iter().product());
    // The mask shows what the figures count, pass by pass.
    let count = |label: u16| mask.voxels().iter().filter(|&&l| l == label).count();
    assert_eq!(count(LABEL_SEEN_FORWARD), seen.seen_forward());
    assert_eq!(
        count(LABEL_SEEN_FORWARD) + count(LABEL_SEEN_BACK_ONLY),
        seen.seen_forward_backward()
    );
    assert!(count(LABEL_SEEN_BACK_ONLY) > 0);
    assert_eq!(
        count(LABEL_SEEN_FORWARD) + count(LABEL_SEEN_BACK_ONLY) + count(LABEL_UNSEEN),
        seen.wall_voxels()
    );
    let overview = seen.overview(&lumen, &geometry, [64, 48]).unwrap();
    assert_eq!([overview.image.width(), overview.image.height()], [64, 48]);
    let alone = WallSeen::forward_only(forward.clone());
    assert_eq!(alone.both(), alone.forward());
    assert_eq!(alone.seen_forward_backward(), forward.seen_count());
    let keys = Route::from_key_frames(vec![KeyFrame::new(
        DVec3::ZERO,
        DVec3::Z,
        DVec3::Y,
        60.0,
        -500.0,
        1.0,
    )
    .unwrap()])
    .unwrap();
    assert!(
        BackwardPass::new(renderer.clone(), &keys, &options, 5.0, 5.0, &forward)
            .unwrap()
            .is_none()
    );
}
