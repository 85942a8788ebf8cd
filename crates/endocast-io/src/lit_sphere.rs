//! The lighting options of the realistic look by name, as `--lighting` and Python's
//! `lighting=` take them: `phong`, `ibl` (the built-in lit sphere) or `ibl:FILE.png` (a user's
//! lit sphere: a square PNG of a lit ball, read as its luminance like a detail texture).

use crate::error::{ReadError, Result};
use crate::texture::read_texture;
use endocast_core::look::{Lighting, LitSphere};
use std::path::Path;
use std::sync::Arc;

/// The lighting `spec` names: `phong`, `ibl` or `ibl:FILE.png` (ASCII case of the names
/// ignored). Errors say what is accepted, or name the file and what is wrong with it.
pub fn named_or_file(spec: &str) -> Result<Lighting> {
    let spec = spec.trim();
    if spec.eq_ignore_ascii_case("phong") {
        return Ok(Lighting::Phong);
    }
    if spec.eq_ignore_ascii_case("ibl") {
        return Ok(Lighting::built_in_ibl());
    }
    let file = spec
        .get(..4)
        .filter(|head| head.eq_ignore_ascii_case("ibl:"))
        .map(|_| &spec[4..]);
    let Some(file) = file else {
        return Err(ReadError::format(
            Path::new(spec),
            "unknown lighting; choose phong, ibl or ibl:FILE.png (a lit sphere)",
        ));
    };
    let path = Path::new(file);
    let map = read_texture(path)?;
    let sphere = LitSphere::new(map).map_err(|e| ReadError::format(path, e.to_string()))?;
    Ok(Lighting::LitSphere(Arc::new(sphere)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_files() {
        assert_eq!(named_or_file(" Phong").unwrap(), Lighting::Phong);
        assert_eq!(named_or_file("IBL").unwrap().name(), "ibl");
        let unknown = named_or_file("matcap").unwrap_err().to_string();
        assert!(unknown.contains("phong, ibl or ibl:FILE.png"), "{unknown}");
        let dir = std::env::temp_dir().join(format!("endocast-lit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let missing = dir.join("missing.png");
        let e = named_or_file(&format!("ibl:{}", missing.display())).unwrap_err();
        assert!(e.to_string().contains("missing.png"), "{e}");
        let text = dir.join("not.png");
        std::fs::write(&text, "not an image").unwrap();
        let e = named_or_file(&format!("ibl:{}", text.display())).unwrap_err();
        assert!(e.to_string().contains("not a readable PNG"), "{e}");
        let wide = dir.join("wide.png");
        crate::write_image_rgb8(&wide, 4, 2, &[128; 4 * 2 * 3]).unwrap();
        let e = named_or_file(&format!("ibl:{}", wide.display())).unwrap_err();
        assert!(e.to_string().contains("square image"), "{e}");
        let square = dir.join("square.png");
        crate::write_image_rgb8(&square, 3, 3, &[255; 3 * 3 * 3]).unwrap();
        let Lighting::LitSphere(sphere) =
            named_or_file(&format!("ibl:{}", square.display())).unwrap()
        else {
            panic!("a lit sphere");
        };
        assert!((sphere.light(0.3, 0.2) - 1.0).abs() < 1e-6);
        std::fs::remove_dir_all(dir).unwrap();
    }
}
