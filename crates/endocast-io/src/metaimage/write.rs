//! The MetaImage writer: one `.mha` file, header then uncompressed little-endian voxels.

use super::header::ELEMENT_TYPES;
use super::itk_orientation;
use crate::atomic::write_file;
use crate::encode::SampleEncoding;
use crate::error::{ReadError, Result};
use endocast_core::Volume;
use std::path::Path;

/// Writes `volume` as a MetaImage `.mha` file (`ElementDataFile = LOCAL`, uncompressed).
///
/// MetaImage has no rescale, so values are written as physical values: `MET_SHORT` when the
/// value map is exact (unit scale, integral offset) and the range fits `int16` (CT in HU),
/// `MET_USHORT` when it is exact and fits `uint16`, otherwise `MET_FLOAT` (float precision;
/// reading it back requantises the range onto 16 bits). Geometry: `TransformMatrix` (the
/// direction's columns, one after another), `Offset`, `ElementSpacing`, and the
/// `AnatomicalOrientation` ITK would write for that direction.
pub fn write(path: &Path, volume: &Volume) -> Result<()> {
    let is_mha = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mha"));
    if !is_mha {
        return Err(ReadError::unsupported(
            path,
            "MetaImage output other than .mha (a .mhd header with a separate data file is not written)",
        ));
    }
    let encoding = SampleEncoding::exact_integer(volume).unwrap_or(SampleEncoding::F32Physical);
    let text = header_text(volume, encoding);
    write_file(path, |w| {
        w.write_all(text.as_bytes())?;
        encoding.write_voxels(volume, w)
    })
}

fn header_text(volume: &Volume, encoding: SampleEncoding) -> String {
    let g = volume.geometry();
    let d = g.direction();
    let element = encoding.element_type();
    let met_name = ELEMENT_TYPES
        .iter()
        .find(|(_, ty)| *ty == element)
        .map_or("MET_FLOAT", |(name, _)| name);
    let list = |values: &[f64]| {
        values
            .iter()
            .map(|&v| number(v))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let dims = g.dims().map(|n| n.to_string()).join(" ");
    format!(
        "ObjectType = Image\n\
         NDims = 3\n\
         BinaryData = True\n\
         BinaryDataByteOrderMSB = False\n\
         CompressedData = False\n\
         TransformMatrix = {}\n\
         Offset = {}\n\
         CenterOfRotation = 0 0 0\n\
         AnatomicalOrientation = {}\n\
         ElementSpacing = {}\n\
         DimSize = {dims}\n\
         ElementType = {met_name}\n\
         ElementDataFile = LOCAL\n",
        list(&d.to_cols_array()),
        list(&g.origin_mm().to_array()),
        itk_orientation(g),
        list(&g.spacing_mm().to_array()),
    )
}

/// The shortest text that parses back to exactly `v`; exponent form for tiny or huge values
/// (Rust's plain form would spell out hundreds of zeros), and no `-0`.
fn number(v: f64) -> String {
    let v = v + 0.0;
    if v == 0.0 || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_exact() {
        for v in [
            0.96875,
            -120.5,
            1.0 / 3.0,
            6.123233995736766e-17,
            1e300,
            -0.0,
        ] {
            let text = number(v);
            assert_eq!(text.parse::<f64>().unwrap(), v, "{text}");
            assert!(text.len() < 26, "{text}");
        }
        assert_eq!(number(-0.0), "0");
        assert_eq!(number(1.0), "1");
    }
}
