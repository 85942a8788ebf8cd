//! MATLAB level 4 MAT-files, as far as the `.mat` beside an SPM Analyze pair needs them: a run
//! of matrices, each a 20-byte header (type, rows, columns, imaginary flag, name length, five
//! int32), its NUL-terminated name and its values column by column. The type's thousands digit
//! is the byte order (0 little-endian, 1 big-endian); only full real double matrices (the rest
//! of the type 0) are read, which is what nibabel writes (scipy's `savemat(format='4')`).
//! MATLAB 5 and later files start with a text header instead and are refused.

/// One named matrix.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Matrix {
    pub name: String,
    pub rows: usize,
    pub cols: usize,
    /// Column by column: `values[col * rows + row]`.
    pub values: Vec<f64>,
}

/// The matrices of a level 4 MAT-file, or why it is not one endocast reads.
pub(super) fn parse(bytes: &[u8]) -> Result<Vec<Matrix>, String> {
    if bytes.starts_with(b"MATLAB") {
        return Err("a MATLAB 5 or later MAT-file (only level 4 files are read)".into());
    }
    let mut matrices = Vec::new();
    let mut rest = bytes;
    while !rest.is_empty() {
        let (matrix, size) = parse_one(rest)?;
        matrices.push(matrix);
        rest = &rest[size..];
    }
    Ok(matrices)
}

/// The matrix at the start of `bytes` and the bytes it takes.
fn parse_one(bytes: &[u8]) -> Result<(Matrix, usize), String> {
    let head = bytes
        .get(..20)
        .ok_or("the file ends within a matrix header")?;
    let word = |n: usize, big: bool| {
        let raw = [
            head[4 * n],
            head[4 * n + 1],
            head[4 * n + 2],
            head[4 * n + 3],
        ];
        if big {
            i32::from_be_bytes(raw)
        } else {
            i32::from_le_bytes(raw)
        }
    };
    let big = match (word(0, false), word(0, true)) {
        (0, _) => false,
        (_, 1000) => true,
        (kind, _) => {
            return Err(format!(
                "matrix type {kind}: only full real double matrices are read"
            ))
        }
    };
    let [rows, cols, imaginary, name_len] = [1, 2, 3, 4].map(|n| word(n, big));
    let size = |v: i32| usize::try_from(v).map_err(|_| format!("a negative size ({v})"));
    let (rows, cols, name_len) = (size(rows)?, size(cols)?, size(name_len)?);
    let parts = if imaginary == 0 { 1 } else { 2 };
    let values_len = rows
        .checked_mul(cols)
        .and_then(|n| n.checked_mul(8 * parts))
        .ok_or("a matrix too large")?;
    let total = 20usize
        .checked_add(name_len)
        .and_then(|n| n.checked_add(values_len))
        .filter(|&n| n <= bytes.len())
        .ok_or("the file ends within a matrix")?;
    let name = &bytes[20..20 + name_len];
    let name = String::from_utf8_lossy(name.split(|&b| b == 0).next().unwrap_or_default());
    let real = &bytes[20 + name_len..20 + name_len + values_len / parts];
    let values = real
        .chunks_exact(8)
        .map(|c| {
            let raw: [u8; 8] = c.try_into().unwrap_or_default();
            if big {
                f64::from_be_bytes(raw)
            } else {
                f64::from_le_bytes(raw)
            }
        })
        .collect();
    let matrix = Matrix {
        name: name.into_owned(),
        rows,
        cols,
        values,
    };
    Ok((matrix, total))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One matrix in level 4 layout: type, rows, cols, imaginary, name length, name, values.
    fn encode(name: &str, rows: i32, values: &[f64], big: bool) -> Vec<u8> {
        let int = |v: i32| {
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let cols = values.len() as i32 / rows;
        let mut out = Vec::new();
        for v in [
            if big { 1000 } else { 0 },
            rows,
            cols,
            0,
            name.len() as i32 + 1,
        ] {
            out.extend(int(v));
        }
        out.extend(name.bytes().chain([0]));
        for v in values {
            out.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
        out
    }

    #[test]
    fn matrices_read_in_both_byte_orders() {
        for big in [false, true] {
            let mut bytes = encode("M", 2, &[1.0, 2.0, 3.0, 4.0], big);
            bytes.extend(encode("mat", 1, &[-0.5, 7.0], big));
            let m = parse(&bytes).unwrap();
            assert_eq!(m.len(), 2);
            assert_eq!((m[0].name.as_str(), m[0].rows, m[0].cols), ("M", 2, 2));
            assert_eq!(m[0].values, [1.0, 2.0, 3.0, 4.0]);
            assert_eq!((m[1].name.as_str(), m[1].rows, m[1].cols), ("mat", 1, 2));
            assert_eq!(m[1].values, [-0.5, 7.0]);
        }
    }

    #[test]
    fn other_files_are_refused_with_a_reason() {
        let good = encode("mat", 2, &[1.0, 2.0, 3.0, 4.0], false);
        assert!(parse(b"MATLAB 5.0 MAT-file, Platform: GLNXA64").is_err());
        assert!(parse(&good[..good.len() - 1]).is_err());
        assert!(parse(&good[..12]).is_err());
        let mut single = good.clone();
        single[0] = 10; // float32 values
        assert!(parse(&single).is_err());
        let mut huge = good.clone();
        huge[4..8].copy_from_slice(&i32::MAX.to_le_bytes());
        huge[8..12].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(parse(&huge).is_err());
        let mut negative = good;
        negative[16..20].copy_from_slice(&(-3i32).to_le_bytes());
        assert!(parse(&negative).is_err());
        assert_eq!(parse(&[]).unwrap(), []);
    }
}
