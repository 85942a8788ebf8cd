//! Mutation testing of every reader: thousands of damaged files (truncated at many offsets,
//! flipped bytes, header numbers replaced by 0, negative, huge and NaN values, missing detached
//! files) must each give `Ok` or a clean `Err` — never a panic, never an allocation beyond the
//! configured limit. Truncated files must give `Err`; valid ones must load and keep no more
//! than 1.1 × their voxel bytes (plus a little bookkeeping). Every refusal stays within
//! issue 32's bounds: at most [`MEMORY_BUDGET`] (56 MiB, under its 100 MB) allocated and
//! [`REFUSAL_TIME`] taken.
//!
//! This is its own test binary with a single test so that the counting allocator below measures
//! only the reader under test.

#![allow(unsafe_code)] // the counting allocator; it only forwards to the system allocator
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

use endocast_core::{Geometry, Modality, ValueMap, Volume};
use endocast_io::{open, Limits, OpenOptions};
use glam::{DMat3, DVec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Forwards to the system allocator, keeping the current and peak number of bytes allocated.
struct Counting;

static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call forwards to `System` with the caller's arguments unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let now = CURRENT.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(now, Ordering::Relaxed);
        System.alloc(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
        System.dealloc(ptr, layout);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            let now = CURRENT.fetch_add(new_size - layout.size(), Ordering::Relaxed) + new_size
                - layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        } else {
            CURRENT.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Voxel limit for every case: far above the valid seeds, far below what a lying header claims.
const MAX_VOXELS: u64 = 1 << 20;
/// The most any single read may allocate beyond what was allocated before it (bytes): the
/// voxels at the limit in the widest sample type, plus room for decoders' buffers.
const MEMORY_BUDGET: usize = (MAX_VOXELS as usize) * 8 + (48 << 20);

/// The longest a refusal may take (issue 32: no refusal takes over 2 s).
const REFUSAL_TIME: Duration = Duration::from_secs(2);

/// Bytes a loaded volume may keep beyond 1.1 × its voxel bytes: the `Loaded` record's strings.
const RETAINED_SLACK: usize = 64 << 10;

/// A valid file set: the files (name, bytes) and the one to open.
struct Seed {
    name: &'static str,
    files: Vec<(String, Vec<u8>)>,
    entry: String,
    /// The byte count at the end of the entry file that a reader may legitimately not need
    /// (a text header's final newline), so truncating inside it need not fail.
    optional_tail: usize,
}

/// What a case must give besides "no panic, bounded memory".
#[derive(Clone, Copy, PartialEq, Eq)]
enum Expect {
    Ok,
    Err,
    Either,
}

#[derive(Default)]
struct Tally {
    cases: usize,
    errors: usize,
    failures: Vec<String>,
}

impl Tally {
    /// Opens `entry` in `dir`; records a failure on panic, on exceeding the memory budget, or
    /// when the outcome contradicts `expect`.
    fn check(&mut self, dir: &Path, entry: &str, what: &str, expect: Expect) {
        self.cases += 1;
        let options = options();
        let before = CURRENT.load(Ordering::Relaxed);
        PEAK.store(before, Ordering::Relaxed);
        let start = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            open(&dir.join(entry), &options).map(|loaded| {
                // What a loaded volume keeps: its voxels and little else.
                let retained = CURRENT.load(Ordering::Relaxed).saturating_sub(before);
                (retained, loaded.volume.voxel_bytes())
            })
        }));
        let used = PEAK.load(Ordering::Relaxed).saturating_sub(before);
        let took = start.elapsed();
        if matches!(outcome, Ok(Err(_))) && took > REFUSAL_TIME {
            self.failures
                .push(format!("{what}: refused after {took:?}"));
        }
        match outcome {
            Err(_) => self.failures.push(format!("{what}: panicked")),
            Ok(Ok((retained, voxel_bytes)))
                if retained > voxel_bytes * 11 / 10 + RETAINED_SLACK =>
            {
                self.failures.push(format!(
                    "{what}: keeps {retained} bytes for {voxel_bytes} voxel bytes"
                ));
            }
            Ok(Ok(_)) if expect == Expect::Err => self.failures.push(format!("{what}: accepted")),
            Ok(Ok(_)) => {}
            Ok(Err(e)) if expect == Expect::Ok => self.failures.push(format!("{what}: {e}")),
            Ok(Err(_)) => self.errors += 1,
        }
        if used > MEMORY_BUDGET {
            self.failures
                .push(format!("{what}: allocated {used} bytes"));
        }
    }
}

/// The options of every case: [`MAX_VOXELS`].
fn options() -> OpenOptions {
    let mut options = OpenOptions::default();
    options.limits = Limits::with_max_voxels(MAX_VOXELS);
    options
}

fn small_volume() -> Volume {
    let dims = [9, 7, 5];
    let turn = DMat3::from_rotation_z(0.3) * DMat3::from_rotation_x(-0.2);
    let g = Geometry::new(
        dims,
        DVec3::new(0.7, 0.8, 2.5),
        DVec3::new(-12.0, 30.5, 7.25),
        turn,
    )
    .unwrap();
    let voxels = (0..dims.iter().product::<usize>())
        .map(|i| (i * 37 % 3000) as u16)
        .collect();
    Volume::new(
        g,
        voxels,
        ValueMap::new(1.0, -1024.0).unwrap(),
        Modality::Ct,
    )
    .unwrap()
}

/// Seeds written by our own writers, plus hand-made detached variants and real DICOM files.
fn seeds(dir: &Path) -> Vec<Seed> {
    let volume = small_volume();
    let mut seeds = Vec::new();
    for (name, file, tail) in [
        ("nifti", "v.nii", 0),
        ("nifti-gz", "v.nii.gz", 0),
        ("nrrd", "v.nrrd", 0),
        ("metaimage", "v.mha", 0),
    ] {
        let path = dir.join(file);
        endocast_io::write(&path, &volume).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        seeds.push(Seed {
            name,
            files: vec![(file.to_string(), bytes)],
            entry: file.to_string(),
            optional_tail: tail,
        });
    }
    seeds.push(detached_nrrd(&volume));
    seeds.push(detached_metaimage(&volume));
    seeds.extend(dicom_seeds());
    seeds
}

fn raw_i16(volume: &Volume) -> Vec<u8> {
    let map = volume.value_map();
    volume
        .voxels()
        .iter()
        .flat_map(|&s| (map.physical(s) as i16).to_le_bytes())
        .collect()
}

fn detached_nrrd(volume: &Volume) -> Seed {
    let [x, y, z] = volume.dims();
    let header = format!(
        "NRRD0004\ntype: short\ndimension: 3\nsizes: {x} {y} {z}\nspace: left-posterior-superior\n\
         space directions: (0.7,0,0) (0,0.8,0) (0,0,2.5)\nspace origin: (1,2,3)\n\
         endian: little\nencoding: raw\ndata file: v.raw\n"
    );
    Seed {
        name: "nrrd-detached",
        files: vec![
            ("v.nhdr".into(), header.into_bytes()),
            ("v.raw".into(), raw_i16(volume)),
        ],
        entry: "v.nhdr".into(),
        optional_tail: 1,
    }
}

fn detached_metaimage(volume: &Volume) -> Seed {
    let [x, y, z] = volume.dims();
    let header = format!(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n\
         CompressedData = False\nTransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 1 2 3\n\
         ElementSpacing = 0.7 0.8 2.5\nDimSize = {x} {y} {z}\nElementType = MET_SHORT\n\
         ElementDataFile = v.raw\n"
    );
    Seed {
        name: "metaimage-detached",
        files: vec![
            ("v.mhd".into(), header.into_bytes()),
            ("v.raw".into(), raw_i16(volume)),
        ],
        entry: "v.mhd".into(),
        optional_tail: 1,
    }
}

/// Real DICOM files in several transfer syntaxes, when the shared data is present.
fn dicom_seeds() -> Vec<Seed> {
    let files = [
        ("dicom-explicit-le", "dicom-transfer-syntaxes/1.dcm"),
        ("dicom-big-endian", "dicom-transfer-syntaxes/3.dcm"),
        ("dicom-rle", "dicom-transfer-syntaxes/4.dcm"),
        ("dicom-jpeg-lossless", "dicom-transfer-syntaxes/5.dcm"),
        ("dicom-jpeg-ls", "dicom-transfer-syntaxes/7.dcm"),
        ("dicom-jpeg-2000", "dicom-transfer-syntaxes/9.dcm"),
    ];
    let mut seeds = Vec::new();
    for (name, rel) in files {
        let Some(path) = endocast_testdata::shared_data(rel) else {
            continue;
        };
        let bytes = std::fs::read(&path).expect("a shared DICOM file reads");
        seeds.push(Seed {
            name,
            files: vec![("s.dcm".into(), bytes)],
            entry: "s.dcm".into(),
            optional_tail: 0,
        });
    }
    seeds
}

/// Writes `files` into a fresh folder `dir/case`, replacing the entry's bytes with `entry_bytes`.
fn stage(dir: &Path, seed: &Seed, entry_bytes: Option<&[u8]>, skip: Option<&str>) -> PathBuf {
    let case = dir.join("case");
    let _ = std::fs::remove_dir_all(&case);
    std::fs::create_dir(&case).unwrap();
    for (name, bytes) in &seed.files {
        if Some(name.as_str()) == skip {
            continue;
        }
        let content = if *name == seed.entry {
            entry_bytes.unwrap_or(bytes)
        } else {
            bytes
        };
        std::fs::write(case.join(name), content).unwrap();
    }
    case
}

/// Offsets to truncate at: every byte of the first 600, then 60 spread over the rest.
fn truncation_points(len: usize) -> Vec<usize> {
    let mut points: Vec<usize> = (0..len.min(600)).collect();
    if len > 600 {
        points.extend((0..60).map(|i| 600 + (len - 600) * i / 60));
    }
    points
}

/// A deterministic pseudo-random stream (splitmix64).
fn next(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Text headers: every number in the header replaced, one at a time, by each hostile value.
fn text_number_mutations(bytes: &[u8]) -> Vec<Vec<u8>> {
    const HOSTILE: [&str; 7] = [
        "0",
        "-1",
        "-2147483649",
        "99999999999999999999",
        "nan",
        "inf",
        "1e308",
    ];
    let header_len = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .unwrap_or(bytes.len())
        .min(4096);
    let mut spans = Vec::new();
    let mut start = None;
    for (i, &c) in bytes[..header_len].iter().enumerate() {
        let numeric = c.is_ascii_digit() || c == b'.' || c == b'-';
        match (numeric, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                spans.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    for (s, e) in spans {
        for value in HOSTILE {
            let mut m = bytes[..s].to_vec();
            m.extend_from_slice(value.as_bytes());
            m.extend_from_slice(&bytes[e..]);
            out.push(m);
        }
    }
    out
}

/// NIfTI-1 binary header fields (offset, width) overwritten with hostile values.
fn nifti_field_mutations(bytes: &[u8]) -> Vec<Vec<u8>> {
    // dim[0..8] (i16 at 40), datatype (70), bitpix (72), pixdim[0..8] (f32 at 76), vox_offset (108),
    // scl_slope (112), scl_inter (116), qform/sform codes (252, 254), quatern (256..280), srow (280..328).
    let mut fields: Vec<(usize, usize)> = (0..8).map(|i| (40 + 2 * i, 2)).collect();
    fields.extend([(70, 2), (72, 2), (252, 2), (254, 2)]);
    fields.extend((0..8).map(|i| (76 + 4 * i, 4)));
    fields.extend((108..328).step_by(4).map(|o| (o, 4)));
    let mut out = Vec::new();
    for (offset, width) in fields {
        let values: Vec<Vec<u8>> = if width == 2 {
            [0i16, -1, i16::MAX, i16::MIN]
                .iter()
                .map(|v| v.to_le_bytes().to_vec())
                .collect()
        } else {
            [0.0f32, -1.0, f32::NAN, f32::INFINITY, 3.0e38]
                .iter()
                .map(|v| v.to_le_bytes().to_vec())
                .collect()
        };
        for v in values {
            let mut m = bytes.to_vec();
            if offset + width <= m.len() {
                m[offset..offset + width].copy_from_slice(&v);
                out.push(m);
            }
        }
    }
    out
}

fn mutate_seed(dir: &Path, seed: &Seed, tally: &mut Tally) {
    let entry_bytes = &seed.files.iter().find(|(n, _)| *n == seed.entry).unwrap().1;
    let valid = stage(dir, seed, None, None);
    tally.check(
        &valid,
        &seed.entry,
        &format!("{} valid", seed.name),
        Expect::Ok,
    );

    let len = entry_bytes.len();
    for at in truncation_points(len) {
        let case = stage(dir, seed, Some(&entry_bytes[..at]), None);
        let expect = if at + seed.optional_tail < len {
            Expect::Err
        } else {
            Expect::Either
        };
        tally.check(
            &case,
            &seed.entry,
            &format!("{} truncated at {at}", seed.name),
            expect,
        );
    }
    for (name, bytes) in &seed.files {
        if *name == seed.entry {
            continue;
        }
        let case = stage(dir, seed, None, Some(name));
        tally.check(
            &case,
            &seed.entry,
            &format!("{} without {name}", seed.name),
            Expect::Err,
        );
        let path = case.join(name);
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        tally.check(
            &case,
            &seed.entry,
            &format!("{} with half of {name}", seed.name),
            Expect::Err,
        );
    }
    let mut state = seed.name.len() as u64 * 7919;
    for i in 0..300 {
        let mut m = entry_bytes.clone();
        let at = if i % 2 == 0 {
            next(&mut state) as usize % len.min(1024)
        } else {
            next(&mut state) as usize % len
        };
        m[at] ^= (next(&mut state) % 255 + 1) as u8;
        let case = stage(dir, seed, Some(&m), None);
        tally.check(
            &case,
            &seed.entry,
            &format!("{} byte {at} flipped", seed.name),
            Expect::Either,
        );
    }
    let header_mutations = if seed.name == "nifti" {
        nifti_field_mutations(entry_bytes)
    } else if seed.name.starts_with("nrrd") || seed.name.starts_with("metaimage") {
        text_number_mutations(entry_bytes)
    } else {
        Vec::new()
    };
    for (i, m) in header_mutations.iter().enumerate() {
        let case = stage(dir, seed, Some(m), None);
        tally.check(
            &case,
            &seed.entry,
            &format!("{} header mutation {i}", seed.name),
            Expect::Either,
        );
    }
}

/// Every fuzz seed of a volume reader, read as its fuzz target names it: the valid ones and
/// those kept for issue 32's findings (element lengths past the end, a JPEG stream labelled
/// RLE, nested sequences, sizes far beyond the data, `/dev/zero` as a data file) must load or
/// fail within the memory budget.
fn fuzz_seeds(dir: &Path, tally: &mut Tally) {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds");
    for (target, entry) in [
        ("dicom", "input.dcm"),
        ("nrrd", "input.nrrd"),
        ("metaimage", "input.mha"),
        ("nifti", "input.nii"),
    ] {
        let Ok(files) = std::fs::read_dir(seeds.join(target)) else {
            continue;
        };
        for file in files {
            let file = file.unwrap().path();
            let case = dir.join("case");
            let _ = std::fs::remove_dir_all(&case);
            std::fs::create_dir(&case).unwrap();
            std::fs::write(case.join(entry), std::fs::read(&file).unwrap()).unwrap();
            // A first, unmeasured read initialises the decoders' lazy statics, which stay.
            let _ = catch_unwind(|| open(&case.join(entry), &options()));
            let what = format!("fuzz seed {}", file.display());
            tally.check(&case, entry, &what, Expect::Either);
        }
    }
}

#[test]
fn damaged_files_never_panic_nor_exceed_the_memory_limit() {
    let dir = tempfile::tempdir().unwrap();
    let mut tally = Tally::default();
    // Panics are detected by `catch_unwind` in `Tally::check`; the default hook would only print
    // them (and, with RUST_BACKTRACE set, allocate tens of MB resolving a backtrace).
    std::panic::set_hook(Box::new(|_| {}));
    for seed in seeds(dir.path()) {
        mutate_seed(dir.path(), &seed, &mut tally);
    }
    fuzz_seeds(dir.path(), &mut tally);
    eprintln!(
        "robustness: {} cases, {} clean errors, {} failures",
        tally.cases,
        tally.errors,
        tally.failures.len()
    );
    assert!(tally.cases > 3000, "only {} cases", tally.cases);
    assert!(
        tally.failures.is_empty(),
        "{} failures, first ones:\n{}",
        tally.failures.len(),
        tally
            .failures
            .iter()
            .take(30)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
}
