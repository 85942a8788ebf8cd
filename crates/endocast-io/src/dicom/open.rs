//! Opening a DICOM file through dicom-rs, with pydicom's fallback for a data set encoded in
//! implicit VR under a meta group that says explicit VR little endian (some converters write
//! that): the pre-flight walk ([`super::lengths`]) sees that the data set's first element has
//! no valid VR, and such a file is read with dicom-rs's adaptive decoder only, which looks at
//! that first element to decide, as pydicom does ("Expected explicit VR, but found implicit
//! VR"). Its explicit decoder is never tried on it: that decoder takes the missing VR as UN and
//! the next bytes as a 4-byte length, and reserves whatever they say (gigabytes, found by the
//! fuzzer) before finding the file short.

use crate::error::{ReadError, Result};
use crate::guard;
use dicom_dictionary_std::tags;
use dicom_dictionary_std::uids::IMPLICIT_VR_LITTLE_ENDIAN;
use dicom_encoding::decode::adaptive_le::AdaptiveVRLittleEndianDecoder;
use dicom_encoding::decode::basic::LittleEndianBasicDecoder;
use dicom_encoding::text::SpecificCharacterSet;
use dicom_encoding::transfer_syntax::TransferSyntaxIndex;
use dicom_encoding::Endianness;
use dicom_object::meta::FileMetaTable;
use dicom_object::{DefaultDicomObject, InMemDicomObject, OpenFileOptions};
use dicom_parser::StatefulDecoder;
use dicom_transfer_syntax_registry::TransferSyntaxRegistry;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// How a file's data set is encoded, as the pre-flight walk found it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Body {
    /// As its transfer syntax says.
    AsDeclared,
    /// In implicit VR although its meta group says explicit VR (warn about it).
    Implicit,
}

/// The DICOM object in `path`, whose data set the pre-flight walk found encoded as `body`: up
/// to its pixel data when `header_only`, else whole.
pub(super) fn open(path: &Path, header_only: bool, body: Body) -> Result<DefaultDicomObject> {
    if body == Body::Implicit {
        return match guard::quietly(|| read_adaptive(path)) {
            Ok(Ok(Some(object))) => Ok(object),
            Ok(Ok(None)) => Err(ReadError::format(
                path,
                "not a readable DICOM file: its data set has no valid VR, and its transfer \
                 syntax is not explicit VR little endian",
            )),
            Ok(Err(message)) => Err(ReadError::format(
                path,
                format!("not a readable DICOM file (read as implicit VR): {message}"),
            )),
            Err(panicked) => Err(ReadError::format(path, panicked.to_string())),
        };
    }
    let opened = guard::quietly(|| {
        let options = OpenFileOptions::new();
        let options = if header_only {
            options.read_until(tags::PIXEL_DATA)
        } else {
            options
        };
        options.open_file(path)
    })
    .map_err(|panicked| ReadError::format(path, panicked.to_string()))?;
    opened.map_err(|error| open_error(path, &error))
}

/// The whole file read with the adaptive decoder, when its transfer syntax is explicit VR
/// little endian (native or encapsulated); `None` when it is not.
fn read_adaptive(path: &Path) -> std::result::Result<Option<DefaultDicomObject>, String> {
    let mut file = BufReader::new(std::fs::File::open(path).map_err(|e| e.to_string())?);
    let mut head = [0u8; 132];
    let preamble = file.read_exact(&mut head).is_ok() && &head[128..] == b"DICM";
    file.seek(SeekFrom::Start(if preamble { 128 } else { 0 }))
        .map_err(|e| e.to_string())?;
    let meta = FileMetaTable::from_reader(&mut file).map_err(|e| chain(&e))?;
    // Every little-endian transfer syntax but Implicit VR Little Endian is explicit VR.
    let explicit_le = meta.transfer_syntax() != IMPLICIT_VR_LITTLE_ENDIAN
        && TransferSyntaxRegistry
            .get(meta.transfer_syntax())
            .is_some_and(|ts| ts.endianness() == Endianness::Little);
    if !explicit_le {
        return Ok(None);
    }
    let decoder = StatefulDecoder::new(
        file,
        AdaptiveVRLittleEndianDecoder::default(),
        LittleEndianBasicDecoder,
        SpecificCharacterSet::default(),
    );
    let object = InMemDicomObject::read_dataset(decoder).map_err(|e| chain(&e))?;
    Ok(Some(object.with_exact_meta(meta)))
}

/// Turns a dicom-object open error into ours: an unknown or undecodable transfer syntax is
/// [`ReadError::Unsupported`], anything else a format error.
pub(super) fn open_error(path: &Path, error: &dicom_object::ReadError) -> ReadError {
    use dicom_object::ReadError as E;
    match error {
        E::OpenFile { source, .. } | E::ReadFile { source, .. } => {
            ReadError::io(path, std::io::Error::new(source.kind(), source.to_string()))
        }
        E::ReadUnrecognizedTransferSyntax { uid, .. } => ReadError::unsupported(
            path,
            format!("transfer syntax {uid} (not a transfer syntax this reader knows)"),
        ),
        E::ReadUnsupportedTransferSyntax { uid, name, .. }
        | E::ReadUnsupportedTransferSyntaxWithSuggestion { uid, name, .. } => {
            ReadError::unsupported(path, format!("transfer syntax {uid} ({name})"))
        }
        other => ReadError::format(path, format!("not a readable DICOM file: {}", chain(other))),
    }
}

/// An error and its causes in one line, so that "premature end" says where.
pub(super) fn chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}
