//! The Analyze 7.5 reader on arbitrary bytes: the first 348 are the `.hdr`; the next byte,
//! doubled, is the length of the `.mat` beside it, which follows; the rest is the `.img`.
//! `Ok` or a clean `Err`, never a panic or a runaway allocation.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (header, rest) = data.split_at(data.len().min(348));
    let (mat_len, rest) = rest
        .split_first()
        .map_or((0, rest), |(&n, rest)| (usize::from(n) * 2, rest));
    let (mat, image) = rest.split_at(rest.len().min(mat_len));
    endocast_fuzz::file_with("input.mat", mat);
    endocast_fuzz::file_with("input.img", image);
    let path = endocast_fuzz::file_with("input.hdr", header);
    let _ = endocast_io::nifti::read(&path, &endocast_fuzz::options());
});
