//! Placeholder until the phantoms land (API as promised in the crate doc).
#![allow(missing_docs)]
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;
#[derive(Debug, Clone, Copy)]
pub enum Phantom {
    SphereShell,
}
impl Phantom {
    pub const ALL: [Phantom; 1] = [Phantom::SphereShell];
    pub fn name(self) -> &'static str {
        "sphere-shell"
    }
    pub fn from_name(n: &str) -> Option<Self> {
        (n == "sphere-shell").then_some(Self::SphereShell)
    }
    pub fn build(self, o: &PhantomOptions) -> Volume {
        let g = Geometry::axis_aligned([o.size; 3], DVec3::ONE, DVec3::ZERO).unwrap();
        Volume::new(
            g,
            vec![0; o.size.pow(3)],
            ValueMap::new(1.0, -1024.0).unwrap(),
            Modality::Ct,
        )
        .unwrap()
    }
}
#[non_exhaustive]
pub struct PhantomOptions {
    pub size: usize,
    pub noise_hu: f64,
    pub seed: u64,
}
impl Default for PhantomOptions {
    fn default() -> Self {
        Self {
            size: 128,
            noise_hu: 0.0,
            seed: 1,
        }
    }
}
