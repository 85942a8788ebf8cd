//! One volume written as NIfTI, NRRD and MetaImage reads back with the same geometry and
//! values from all three: the formats' conventions (RAS vs LPS, row- vs column-major matrices,
//! rescale fields) are all undone correctly.

use crate::test_volumes::{assert_same_volume, oblique_ct, sheared_ct};
use endocast_io::{open, write, OpenOptions};

#[test]
fn nifti_nrrd_and_metaimage_agree() {
    let dir = tempfile::tempdir().unwrap();
    for original in [oblique_ct(), sheared_ct()] {
        let read_back: Vec<_> = ["v.nii.gz", "v.nrrd", "v.mha"]
            .iter()
            .map(|name| {
                let path = dir.path().join(name);
                write(&path, &original).unwrap();
                open(&path, &OpenOptions::default()).unwrap().volume
            })
            .collect();
        for volume in &read_back {
            assert_same_volume(volume, &original, 1e-5);
        }
        assert_same_volume(&read_back[0], &read_back[1], 1e-5);
        assert_same_volume(&read_back[1], &read_back[2], 1e-5);
    }
}
