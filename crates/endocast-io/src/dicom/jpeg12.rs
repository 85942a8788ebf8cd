//! 12-bit JPEG (ISO 10918-1 extended sequential DCT, Huffman coded: DICOM's "JPEG Extended
//! (Process 2 & 4)", 1.2.840.10008.1.2.4.51) for grey-scale frames. jpeg-decoder and
//! zune-jpeg decode only 8-bit DCT streams, and libjpeg's 12-bit build would need cmake, so the
//! one component such frames have is decoded here: Huffman tables, 8- or 16-bit quantisation
//! tables, restart intervals, and an exact floating-point inverse DCT (the standard's formula;
//! decoders may differ from one another by one unit where a value rounds half-way).
//!
//! Every length and index is checked against the stream, so a damaged stream is an error
//! rather than a panic or an allocation it did not pay for.

use std::f64::consts::PI;

/// Whether `data` is a JPEG stream whose frame header (SOF1) declares 12-bit samples.
pub(super) fn is_12_bit(data: &[u8]) -> bool {
    let mut parser = Parser { data, at: 2 };
    data.starts_with(&[0xFF, 0xD8])
        && std::iter::from_fn(|| parser.segment().ok().flatten())
            .take(64)
            .find(|(marker, _)| (0xC0..=0xC3).contains(marker) || *marker == 0xDA)
            .is_some_and(|(marker, body)| marker == 0xC1 && body.first() == Some(&12))
}

/// The samples of a one-component 12-bit (or 8-bit) sequential JPEG stream of `rows` ×
/// `columns`, row by row.
pub(super) fn decode(data: &[u8], rows: u16, columns: u16) -> Result<Vec<u16>, String> {
    if !data.starts_with(&[0xFF, 0xD8]) {
        return Err("not a JPEG stream (no SOI marker)".into());
    }
    let mut tables = Tables::default();
    let mut parser = Parser { data, at: 2 };
    while let Some((marker, body)) = parser.segment()? {
        match marker {
            0xDB => tables.quantisation(body)?,
            0xC4 => tables.huffman(body)?,
            0xDD => tables.restart = u32::from(be16(body, 0)?),
            0xC0 | 0xC1 => tables.frame(body, rows, columns)?,
            0xC2 | 0xC3 | 0xC5..=0xC7 | 0xC9..=0xCB | 0xCD..=0xCF => {
                return Err(format!(
                    "JPEG frame type SOF{} (only sequential DCT frames are read here)",
                    marker - 0xC0
                ))
            }
            0xDA => {
                let scan = tables.scan(body)?;
                return scan.decode(&data[parser.at..]);
            }
            0xD9 => break,
            _ => {}
        }
    }
    Err("the JPEG stream has no scan".into())
}

fn be16(data: &[u8], at: usize) -> Result<u16, String> {
    data.get(at..at + 2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .ok_or_else(|| "a JPEG marker segment ends early".into())
}

/// Walks the marker segments before the entropy-coded data.
struct Parser<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Parser<'a> {
    /// The next marker and its segment body (empty for markers without one); `None` at the
    /// end of the data.
    fn segment(&mut self) -> Result<Option<(u8, &'a [u8])>, String> {
        while self.data.get(self.at..self.at + 2) == Some(&[0xFF, 0xFF]) {
            self.at += 1;
        }
        let Some(&[0xFF, marker]) = self.data.get(self.at..self.at + 2) else {
            return if self.at >= self.data.len() {
                Ok(None)
            } else {
                Err(format!("expected a JPEG marker at byte {}", self.at))
            };
        };
        self.at += 2;
        if matches!(marker, 0x01 | 0xD0..=0xD9) {
            return Ok(Some((marker, &[][..])));
        }
        let length = usize::from(be16(self.data, self.at)?);
        let body = self
            .data
            .get(self.at + 2..self.at + length.max(2))
            .ok_or("a JPEG marker segment runs past the end of the stream")?;
        self.at += length.max(2);
        Ok(Some((marker, body)))
    }
}

/// A Huffman table in the form of ISO 10918-1 F.2.2.3.
#[derive(Clone, Default)]
struct Huffman {
    /// Largest code of each length (1–16), −1 when there is none.
    max_code: [i32; 17],
    /// Index into `values` of the first code of each length, minus that code.
    offset: [i32; 17],
    values: Vec<u8>,
}

impl Huffman {
    fn new(counts: &[u8], values: &[u8]) -> Self {
        let mut table = Self {
            max_code: [-1; 17],
            offset: [0; 17],
            values: values.to_vec(),
        };
        let (mut code, mut index) = (0i32, 0i32);
        for (length, &count) in (1..=16).zip(counts) {
            table.offset[length] = index - code;
            if count > 0 {
                index += i32::from(count);
                code += i32::from(count);
                table.max_code[length] = code - 1;
            }
            code <<= 1;
        }
        table
    }
}

#[derive(Default)]
struct Tables {
    quantisation: [Option<[u16; 64]>; 4],
    dc: [Option<Huffman>; 4],
    ac: [Option<Huffman>; 4],
    restart: u32,
    /// Precision (bits), columns, rows and quantisation table of the one component.
    frame: Option<(u8, usize, usize, usize)>,
}

impl Tables {
    fn quantisation(&mut self, mut body: &[u8]) -> Result<(), String> {
        while let Some((&head, rest)) = body.split_first() {
            let wide = head >> 4 == 1;
            let size = if wide { 128 } else { 64 };
            let values = rest.get(..size).ok_or("a JPEG DQT segment ends early")?;
            let mut table = [0u16; 64];
            for (k, entry) in table.iter_mut().enumerate() {
                *entry = if wide {
                    u16::from_be_bytes([values[2 * k], values[2 * k + 1]])
                } else {
                    u16::from(values[k])
                };
            }
            *self
                .quantisation
                .get_mut(usize::from(head & 15))
                .ok_or("a JPEG DQT table number above 3")? = Some(table);
            body = &rest[size..];
        }
        Ok(())
    }

    fn huffman(&mut self, mut body: &[u8]) -> Result<(), String> {
        while let Some((&head, rest)) = body.split_first() {
            let counts = rest.get(..16).ok_or("a JPEG DHT segment ends early")?;
            let total: usize = counts.iter().map(|&c| usize::from(c)).sum();
            let values = rest
                .get(16..16 + total)
                .ok_or("a JPEG DHT segment ends early")?;
            let slot = match head >> 4 {
                0 => self.dc.get_mut(usize::from(head & 15)),
                _ => self.ac.get_mut(usize::from(head & 15)),
            };
            *slot.ok_or("a JPEG DHT table number above 3")? = Some(Huffman::new(counts, values));
            body = &rest[16 + total..];
        }
        Ok(())
    }

    fn frame(&mut self, body: &[u8], rows: u16, columns: u16) -> Result<(), String> {
        let precision = *body.first().ok_or("a JPEG SOF segment ends early")?;
        let (height, width) = (be16(body, 1)?, be16(body, 3)?);
        if body.get(5) != Some(&1) {
            return Err("the JPEG frame has more than one component (not grey-scale)".into());
        }
        if (height, width) != (rows, columns) {
            return Err(format!(
                "the JPEG stream holds {height} rows × {width} columns, but Rows × Columns \
                 declare {rows} × {columns}"
            ));
        }
        if !matches!(precision, 8 | 12) {
            return Err(format!(
                "JPEG sample precision {precision} (8 or 12 expected)"
            ));
        }
        let table = usize::from(*body.get(8).ok_or("a JPEG SOF segment ends early")?);
        self.frame = Some((precision, usize::from(width), usize::from(height), table));
        Ok(())
    }

    fn scan(&self, body: &[u8]) -> Result<Scan<'_>, String> {
        let (precision, width, height, q) = self.frame.ok_or("a JPEG scan before its frame")?;
        if body.first() != Some(&1) {
            return Err("the JPEG scan has more than one component".into());
        }
        let selector = *body.get(2).ok_or("a JPEG SOS segment ends early")?;
        Ok(Scan {
            precision,
            width,
            height,
            restart: self.restart,
            quantisation: self
                .quantisation
                .get(q)
                .and_then(|t| t.as_ref())
                .ok_or_else(|| {
                    format!("the JPEG frame names quantisation table {q}, never defined")
                })?,
            dc: pick(&self.dc, selector >> 4)?,
            ac: pick(&self.ac, selector & 15)?,
        })
    }
}

/// Huffman table `n` of `tables`, which the scan names.
fn pick(tables: &[Option<Huffman>; 4], n: u8) -> Result<&Huffman, String> {
    tables
        .get(usize::from(n))
        .and_then(Option::as_ref)
        .ok_or_else(|| format!("the JPEG scan names Huffman table {n}, never defined"))
}

/// One scan of one component, ready to decode.
struct Scan<'a> {
    precision: u8,
    width: usize,
    height: usize,
    restart: u32,
    quantisation: &'a [u16; 64],
    dc: &'a Huffman,
    ac: &'a Huffman,
}

/// Zig-zag position `k` → natural (row-major) index in the 8 × 8 block.
const ZIGZAG: [usize; 64] = [
    0, 1, 8, 16, 9, 2, 3, 10, 17, 24, 32, 25, 18, 11, 4, 5, 12, 19, 26, 33, 40, 48, 41, 34, 27, 20,
    13, 6, 7, 14, 21, 28, 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51, 58, 59,
    52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63,
];

impl Scan<'_> {
    fn decode(&self, data: &[u8]) -> Result<Vec<u16>, String> {
        let (across, down) = (self.width.div_ceil(8), self.height.div_ceil(8));
        let mut out = vec![0u16; self.width * self.height];
        let mut bits = Bits::new(data);
        let idct = Idct::new();
        let mut predictor = 0i32;
        let max = f64::from((1u32 << self.precision) - 1);
        let shift = f64::from(1u32 << (self.precision - 1));
        for block in 0..across * down {
            if self.restart > 0 && block > 0 && block % self.restart as usize == 0 {
                bits.restart()?;
                predictor = 0;
            }
            let coefficients = self.block(&mut bits, &mut predictor)?;
            let samples = idct.inverse(&coefficients);
            let (bx, by) = (block % across * 8, block / across * 8);
            for (n, value) in samples.iter().enumerate() {
                let (x, y) = (bx + n % 8, by + n / 8);
                if x < self.width && y < self.height {
                    out[y * self.width + x] = (value.round() + shift).clamp(0.0, max) as u16;
                }
            }
        }
        Ok(out)
    }

    /// The dequantised coefficients of the next block, in natural order.
    fn block(&self, bits: &mut Bits<'_>, predictor: &mut i32) -> Result<[f64; 64], String> {
        let mut coefficients = [0f64; 64];
        let size = bits.symbol(self.dc)?;
        *predictor = predictor.saturating_add(bits.extended(size)?);
        coefficients[0] = f64::from(*predictor) * f64::from(self.quantisation[0]);
        let mut k = 1;
        while k < 64 {
            let symbol = bits.symbol(self.ac)?;
            let (run, size) = (usize::from(symbol >> 4), symbol & 15);
            if size == 0 {
                if run != 15 {
                    break;
                }
                k += 16;
                continue;
            }
            k += run;
            if k > 63 {
                return Err("a JPEG block has more than 64 coefficients".into());
            }
            let value = f64::from(bits.extended(size)?) * f64::from(self.quantisation[k]);
            coefficients[ZIGZAG[k]] = value;
            k += 1;
        }
        Ok(coefficients)
    }
}

/// The entropy-coded bits, with stuffed zero bytes removed; a marker ends them (zeros follow).
struct Bits<'a> {
    data: &'a [u8],
    at: usize,
    buffer: u32,
    count: u32,
}

impl<'a> Bits<'a> {
    fn new(data: &'a [u8]) -> Self {
        Self {
            data,
            at: 0,
            buffer: 0,
            count: 0,
        }
    }

    fn bit(&mut self) -> Result<u32, String> {
        if self.count == 0 {
            let ended = || "the JPEG scan ends before its last block".to_string();
            let byte = *self.data.get(self.at).ok_or_else(ended)?;
            // 0xFF is followed by a stuffed zero; anything else is a marker ending the scan.
            self.at += match (byte, self.data.get(self.at + 1)) {
                (0xFF, Some(&0)) => 2,
                (0xFF, _) => return Err(ended()),
                _ => 1,
            };
            self.buffer = u32::from(byte);
            self.count = 8;
        }
        self.count -= 1;
        Ok((self.buffer >> self.count) & 1)
    }

    /// A Huffman-coded symbol (ISO 10918-1 F.2.2.3).
    fn symbol(&mut self, table: &Huffman) -> Result<u8, String> {
        let mut code = self.bit()? as i32;
        for length in 1..=16 {
            if code <= table.max_code[length] {
                let index = table.offset[length] + code;
                return usize::try_from(index)
                    .ok()
                    .and_then(|i| table.values.get(i).copied())
                    .ok_or_else(|| "a JPEG Huffman code outside its table".into());
            }
            code = (code << 1) | self.bit()? as i32;
        }
        Err("a JPEG Huffman code longer than 16 bits".into())
    }

    /// A `size`-bit magnitude, sign-extended (ISO 10918-1 F.2.2.1, EXTEND).
    fn extended(&mut self, size: u8) -> Result<i32, String> {
        if size == 0 {
            return Ok(0);
        }
        if size > 16 {
            return Err(format!("a JPEG coefficient of {size} bits"));
        }
        let mut value = 0i32;
        for _ in 0..size {
            value = (value << 1) | self.bit()? as i32;
        }
        Ok(if value < 1 << (size - 1) {
            value - (1 << size) + 1
        } else {
            value
        })
    }

    /// Skips to the byte after the next RSTn marker, forgetting buffered bits.
    fn restart(&mut self) -> Result<(), String> {
        self.count = 0;
        while self.at + 1 < self.data.len() {
            if self.data[self.at] == 0xFF && (0xD0..=0xD7).contains(&self.data[self.at + 1]) {
                self.at += 2;
                return Ok(());
            }
            self.at += 1;
        }
        Err("a JPEG restart marker is missing".into())
    }
}

/// The separable inverse DCT of ISO 10918-1 A.3.3, in double precision.
struct Idct {
    /// `basis[x][u]` = C(u)/2 · cos((2x + 1)uπ/16).
    basis: [[f64; 8]; 8],
}

impl Idct {
    fn new() -> Self {
        let mut basis = [[0f64; 8]; 8];
        for (x, row) in basis.iter_mut().enumerate() {
            for (u, value) in row.iter_mut().enumerate() {
                let scale = if u == 0 { 0.5 / 2f64.sqrt() } else { 0.5 };
                *value = scale * ((2 * x + 1) as f64 * u as f64 * PI / 16.0).cos();
            }
        }
        Self { basis }
    }

    fn inverse(&self, coefficients: &[f64; 64]) -> [f64; 64] {
        // Rows (over u), then columns (over v).
        let mut rows = [0f64; 64];
        for v in 0..8 {
            for x in 0..8 {
                rows[v * 8 + x] = (0..8)
                    .map(|u| self.basis[x][u] * coefficients[v * 8 + u])
                    .sum();
            }
        }
        let mut out = [0f64; 64];
        for y in 0..8 {
            for x in 0..8 {
                out[y * 8 + x] = (0..8).map(|v| self.basis[y][v] * rows[v * 8 + x]).sum();
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Packs a string of '0'/'1' into bytes, padding the last with ones.
    fn pack(bits: &str) -> Vec<u8> {
        let mut bits = bits.to_owned();
        while !bits.len().is_multiple_of(8) {
            bits.push('1');
        }
        (0..bits.len() / 8)
            .map(|i| u8::from_str_radix(&bits[8 * i..8 * i + 8], 2).unwrap_or(0))
            .collect()
    }

    fn segment(marker: u8, body: &[u8]) -> Vec<u8> {
        let mut out = vec![0xFF, marker];
        out.extend_from_slice(&((body.len() + 2) as u16).to_be_bytes());
        out.extend_from_slice(body);
        out
    }

    /// A 12-bit stream of two 8 × 8 blocks holding 3000 and 1000 (DC only).
    fn two_blocks() -> Vec<u8> {
        let mut stream = vec![0xFF, 0xD8];
        let mut dqt = vec![0x10];
        dqt.extend((0..64).flat_map(|_| 8u16.to_be_bytes()));
        stream.extend(segment(0xDB, &dqt));
        // DC table 0: two codes of length 2 (00 → size 10, 01 → size 11); AC table 0: EOB = 0.
        let mut dc = vec![0x00, 0, 2];
        dc.extend([0; 14]);
        dc.extend([10, 11]);
        stream.extend(segment(0xC4, &dc));
        let mut ac = vec![0x10, 1];
        ac.extend([0; 15]);
        ac.push(0x00);
        stream.extend(segment(0xC4, &ac));
        stream.extend(segment(0xC1, &[12, 0, 8, 0, 16, 1, 1, 0x11, 0]));
        stream.extend(segment(0xDA, &[1, 1, 0x00, 0, 63, 0]));
        // 3000 = 2048 + 952 (size 10); then 1000 = 3000 − 2000, −2000 as 47 in 11 bits.
        stream.extend(pack(&format!("00{:010b}001{:011b}0", 952, 47)));
        stream.extend([0xFF, 0xD9]);
        stream
    }

    #[test]
    fn decodes_dc_only_12_bit_blocks() {
        let stream = two_blocks();
        assert!(is_12_bit(&stream));
        let samples = decode(&stream, 8, 16).unwrap_or_default();
        assert_eq!(samples.len(), 128);
        for y in 0..8 {
            assert_eq!(samples[y * 16], 3000);
            assert_eq!(samples[y * 16 + 7], 3000);
            assert_eq!(samples[y * 16 + 8], 1000);
            assert_eq!(samples[y * 16 + 15], 1000);
        }
    }

    #[test]
    fn refuses_damaged_streams_without_panicking() {
        let stream = two_blocks();
        assert!(decode(&stream, 8, 8).is_err());
        for end in 0..stream.len() {
            let _ = decode(&stream[..end], 8, 16);
        }
        let mut flipped = stream.clone();
        for i in 2..flipped.len() {
            flipped[i] ^= 0x5A;
            let _ = decode(&flipped, 8, 16);
            flipped[i] ^= 0x5A;
        }
    }
}
