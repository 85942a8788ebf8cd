//! The projections a camera can have, and their field-of-view ranges.

/// How a camera maps view directions to image positions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Projection {
    /// Perspective (a rectilinear lens): straight lines stay straight; field of view < 180°.
    #[default]
    Pinhole,
    /// Fisheye, equidistant: the image radius grows with the angle from the axis (r = f·θ).
    Equidistant,
    /// Fisheye, equisolid-angle: r = 2f·sin(θ/2), equal solid angles get equal areas.
    Equisolid,
    /// Parallel rays along the view direction (overviews and checks); the field of view is a
    /// height in mm.
    Orthographic,
    /// The unfolded cube: six 90° pinhole faces around the eye in a cross (see
    /// [`super::cube`]); the field is fixed at 90°.
    Cube,
    /// A 360° equirectangular panorama around the camera's up vector, the seam behind the eye
    /// (see [`super::panorama`]); the field is the latitudes it spans, 10°–180°.
    Panorama,
}

impl Projection {
    /// Every projection, in a fixed order.
    pub const ALL: [Projection; 6] = [
        Self::Pinhole,
        Self::Equidistant,
        Self::Equisolid,
        Self::Orthographic,
        Self::Cube,
        Self::Panorama,
    ];

    /// The name the CLI uses: `pinhole`, `equidistant`, `equisolid`, `orthographic`, `cube`,
    /// `panorama`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Pinhole => "pinhole",
            Self::Equidistant => "equidistant",
            Self::Equisolid => "equisolid",
            Self::Orthographic => "orthographic",
            Self::Cube => "cube",
            Self::Panorama => "panorama",
        }
    }

    /// Every projection's name, for messages: "pinhole, equidistant, …, cube or panorama".
    pub fn choices() -> String {
        let names: Vec<&str> = Self::ALL.iter().map(|p| p.name()).collect();
        let (last, rest) = names.split_last().unwrap_or((&"", &[]));
        format!("{} or {last}", rest.join(", "))
    }

    /// The projection called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name.trim()))
    }
}

impl Projection {
    /// Whether this is one of the fisheye projections (the field is an angle across the image
    /// circle, and rays at more than 90° from the axis exist).
    pub fn is_fisheye(self) -> bool {
        matches!(self, Self::Equidistant | Self::Equisolid)
    }

    /// Whether this is an all-round view (the cube or the panorama): it shows directions all
    /// around the eye, so it has no lens distortion, vignetting or stereo eyes.
    pub fn is_all_round(self) -> bool {
        matches!(self, Self::Cube | Self::Panorama)
    }

    /// The field a view with this projection gets when no one gives one, if the projection
    /// fixes it: the cube's 90° faces, the panorama's whole sphere (180° of latitude).
    pub fn default_field(self) -> Option<f64> {
        match self {
            Self::Cube => Some(90.0),
            Self::Panorama => Some(180.0),
            _ => None,
        }
    }

    /// The accepted range of the field: degrees for the angular projections (pinhole
    /// [`FOV_RANGE_DEG`](super::FOV_RANGE_DEG), fisheye 10°–360°), mm of view height for the
    /// orthographic one; the cube's faces are always 90°, the panorama spans 10°–180° of
    /// latitude.
    pub fn field_range(self) -> (f64, f64) {
        match self {
            Self::Pinhole => super::FOV_RANGE_DEG,
            Self::Equidistant | Self::Equisolid => (10.0, 360.0),
            Self::Orthographic => (1e-3, 1e6),
            Self::Cube => (90.0, 90.0),
            Self::Panorama => (10.0, 180.0),
        }
    }

    /// The unit of the field, in words.
    pub fn field_unit(self) -> &'static str {
        match self {
            Self::Orthographic => "mm of view height",
            Self::Cube => "degrees per face (fixed)",
            Self::Panorama => "degrees of latitude",
            _ => "degrees of field of view",
        }
    }
}
