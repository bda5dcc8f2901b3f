//! ISO 25178-72 `.x3p` (XML 3D surface profile): a zip archive holding
//! `main.xml` (axes, pixel increments, the data's type and size) and the
//! binary heights it links (`bindata/data.bin`, x fastest, little endian).
//! Read: areal maps (`FeatureType` SUR) on incremental x, y axes with
//! heights of type D (f64), F (f32), L (u32) or I (u16), scaled by the z
//! axis's increment when it has one; NaN heights are missing points.
//! Units are metres, as the standard says. Written: what the reader
//! reads (D or F), for the tests and `mpcontact.convert`.

use super::{npy::reason_of, open_regular, ScanFileError};
use roxmltree::{Document, Node};
use solver::Scan;
use std::io::{Read, Write};
use std::path::Path;

/// The most points a scan may have (a 16384² map): the limit keeps a
/// corrupt size field from asking for terabytes.
pub const MAX_POINTS: u64 = 1 << 28;

/// The largest `main.xml` read (its metadata is a few kilobytes).
const MAX_XML_BYTES: u64 = 16 << 20;

/// The binary type of the heights (`CZ/DataType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataType {
    /// 64-bit float.
    D,
    /// 32-bit float.
    F,
    /// 32-bit unsigned integer.
    L,
    /// 16-bit unsigned integer.
    I,
}

impl DataType {
    fn bytes(self) -> usize {
        match self {
            DataType::D => 8,
            DataType::F | DataType::L => 4,
            DataType::I => 2,
        }
    }
}

/// The child element of `node` named `name` (any namespace).
fn child<'a, 'i>(node: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

/// The text of the element at `path` below `node`, trimmed.
fn text<'a>(node: Node<'a, '_>, path: &[&str]) -> Option<&'a str> {
    let mut at = node;
    for name in path {
        at = child(at, name)?;
    }
    at.text().map(str::trim)
}

/// Reads the `.x3p` at `path`.
pub fn read(path: &Path) -> Result<Scan, ScanFileError> {
    let bad = |reason: String| ScanFileError::new(path, reason);
    let (file, _) = open_regular(path)?;
    let mut zip = zip::ZipArchive::new(std::io::BufReader::new(file)).map_err(|e| {
        bad(format!(
            "not a readable .x3p: an .x3p is a zip archive of main.xml and binary heights, and this one is corrupt or truncated ({e})"
        ))
    })?;
    let xml = {
        let entry = zip
            .by_name("main.xml")
            .map_err(|e| bad(format!("no main.xml in the archive ({e}): not an .x3p")))?;
        let mut text = String::new();
        entry
            .take(MAX_XML_BYTES)
            .read_to_string(&mut text)
            .map_err(|e| bad(format!("main.xml cannot be read: {e}")))?;
        text
    };
    let doc = Document::parse(&xml).map_err(|e| bad(format!("main.xml is not XML: {e}")))?;
    let root = doc.root_element();
    let record1 = child(root, "Record1").ok_or_else(|| bad("main.xml has no Record1".into()))?;
    let record3 = child(root, "Record3").ok_or_else(|| bad("main.xml has no Record3".into()))?;
    match text(record1, &["FeatureType"]) {
        Some("SUR") => {}
        Some("PRF") => {
            return Err(bad(
                "a 1-D profile (FeatureType PRF): contact needs an areal map (SUR)".into(),
            ))
        }
        Some(other) => {
            return Err(bad(format!(
                "FeatureType {other}: only areal maps (SUR) on a regular grid are read"
            )))
        }
        None => return Err(bad("main.xml has no Record1/FeatureType".into())),
    }
    let axes = child(record1, "Axes").ok_or_else(|| bad("main.xml has no Record1/Axes".into()))?;
    let number = |path: &[&str]| -> Result<f64, ScanFileError> {
        let t = text(axes, path)
            .ok_or_else(|| bad(format!("main.xml has no Axes/{}", path.join("/"))))?;
        t.parse::<f64>()
            .map_err(|_| bad(format!("Axes/{} is `{t}`, not a number", path.join("/"))))
    };
    for (axis, want) in [("CX", "I"), ("CY", "I"), ("CZ", "A")] {
        let got = text(axes, &[axis, "AxisType"]);
        if got != Some(want) {
            return Err(bad(format!(
                "Axes/{axis}/AxisType is {got:?}: only incremental x, y axes (I) and absolute heights (A) are read"
            )));
        }
    }
    let (dx, dy) = (number(&["CX", "Increment"])?, number(&["CY", "Increment"])?);
    let dtype = match text(axes, &["CZ", "DataType"]) {
        Some("D") => DataType::D,
        Some("F") => DataType::F,
        Some("L") => DataType::L,
        Some("I") => DataType::I,
        other => {
            return Err(bad(format!(
                "Axes/CZ/DataType is {other:?}: one of D, F, L, I"
            )))
        }
    };
    let z_scale = match child(axes, "CZ").and_then(|z| child(z, "Increment")) {
        Some(_) => Some(number(&["CZ", "Increment"])?),
        None => None,
    };
    let size = |name: &str| -> Result<u64, ScanFileError> {
        let t = text(record3, &["MatrixDimension", name])
            .ok_or_else(|| bad(format!("main.xml has no Record3/MatrixDimension/{name}")))?;
        t.parse::<u64>()
            .map_err(|_| bad(format!("MatrixDimension/{name} is `{t}`, not a count")))
    };
    let (nx, ny, nz) = (size("SizeX")?, size("SizeY")?, size("SizeZ")?);
    if nz != 1 {
        return Err(bad(format!(
            "MatrixDimension/SizeZ is {nz}: only one layer of heights is read"
        )));
    }
    let points = nx.saturating_mul(ny);
    if points > MAX_POINTS {
        return Err(bad(format!(
            "{nx} x {ny} points, more than the {MAX_POINTS} read"
        )));
    }
    let link = text(record3, &["DataLink", "PointDataLink"]).ok_or_else(|| {
        bad(
            "main.xml has no Record3/DataLink/PointDataLink (inline DataList heights are not read)"
                .into(),
        )
    })?;
    let want = points as usize * dtype.bytes();
    let mut entry = zip.by_name(link).map_err(|e| {
        bad(format!(
            "the heights `{link}` named in main.xml are not in the archive ({e})"
        ))
    })?;
    if entry.size() < want as u64 {
        return Err(bad(format!(
            "the heights `{link}` are {} bytes, too short for {nx} x {ny} values of type {dtype:?} ({want} bytes): the file is truncated or corrupt",
            entry.size()
        )));
    }
    let mut raw = vec![0u8; want];
    entry.read_exact(&mut raw).map_err(|e| {
        bad(format!(
            "the heights `{link}` cannot be read whole: the file is truncated or corrupt ({e})"
        ))
    })?;
    let mut heights: Vec<f64> = match dtype {
        DataType::D => raw
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default()))
            .collect(),
        DataType::F => raw
            .chunks_exact(4)
            .map(|b| f64::from(f32::from_le_bytes(b.try_into().unwrap_or_default())))
            .collect(),
        DataType::L => raw
            .chunks_exact(4)
            .map(|b| f64::from(u32::from_le_bytes(b.try_into().unwrap_or_default())))
            .collect(),
        DataType::I => raw
            .chunks_exact(2)
            .map(|b| f64::from(u16::from_le_bytes(b.try_into().unwrap_or_default())))
            .collect(),
    };
    if let Some(s) = z_scale {
        heights.iter_mut().for_each(|h| *h *= s);
    }
    Scan::new(nx as usize, ny as usize, dx, dy, heights).map_err(|e| bad(reason_of(e)))
}

/// Writes `scan` to `path` as an `.x3p` with heights of type D (f64) or
/// F (f32), NaN where a point is missing; no z increment (heights in m).
pub fn write(path: &Path, scan: &Scan, dtype: DataType) -> Result<(), ScanFileError> {
    let bad = |reason: String| ScanFileError::new(path, reason);
    let data: Vec<u8> = match dtype {
        DataType::D => scan.heights.iter().flat_map(|h| h.to_le_bytes()).collect(),
        DataType::F => scan
            .heights
            .iter()
            .flat_map(|h| (*h as f32).to_le_bytes())
            .collect(),
        other => {
            return Err(bad(format!(
                "heights of type {other:?} are not written (D, F)"
            )))
        }
    };
    let xml = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">
  <Record1>
    <Revision>ISO5436 - 2000</Revision>
    <FeatureType>SUR</FeatureType>
    <Axes>
      <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{dx:e}</Increment><Offset>0</Offset></CX>
      <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{dy:e}</Increment><Offset>0</Offset></CY>
      <CZ><AxisType>A</AxisType><DataType>{dtype:?}</DataType></CZ>
    </Axes>
  </Record1>
  <Record2>
    <Instrument><Manufacturer>mpcontact</Manufacturer><Model>mpcontact</Model><Serial>not available</Serial><Version>{version}</Version></Instrument>
  </Record2>
  <Record3>
    <MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>
    <DataLink><PointDataLink>bindata/data.bin</PointDataLink></DataLink>
  </Record3>
</p:ISO5436_2>
"#,
        dx = scan.dx,
        dy = scan.dy,
        nx = scan.nx,
        ny = scan.ny,
        version = env!("CARGO_PKG_VERSION"),
    );
    let file = std::fs::File::create(path).map_err(|e| bad(format!("cannot write: {e}")))?;
    let mut zip = zip::ZipWriter::new(std::io::BufWriter::new(file));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .large_file(data.len() as u64 > u32::MAX as u64 / 2);
    let zerr = |e: zip::result::ZipError| bad(format!("cannot write: {e}"));
    zip.start_file("main.xml", options).map_err(zerr)?;
    zip.write_all(xml.as_bytes())
        .map_err(|e| bad(format!("cannot write: {e}")))?;
    zip.start_file("bindata/data.bin", options).map_err(zerr)?;
    zip.write_all(&data)
        .map_err(|e| bad(format!("cannot write: {e}")))?;
    zip.finish().map_err(zerr)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What is written is read back to the bit (f64), or as its f32
    /// rounding (F); NaN stays missing; pixels need not be square.
    #[test]
    fn an_x3p_reads_back_what_was_written() {
        let dir = tempfile::tempdir().unwrap();
        let mut h: Vec<f64> = (0..7 * 5).map(|i| (i as f64 * 0.37).sin() * 1e-6).collect();
        h[8] = f64::NAN;
        let scan = Scan::new(7, 5, 0.3e-6, 1.1e-6, h).unwrap();
        for dtype in [DataType::D, DataType::F] {
            let path = dir.path().join(format!("s{dtype:?}.x3p"));
            write(&path, &scan, dtype).unwrap();
            let back = read(&path).unwrap();
            assert_eq!((back.nx, back.ny, back.dx, back.dy), (7, 5, 0.3e-6, 1.1e-6));
            for (a, b) in scan.heights.iter().zip(back.heights.iter()) {
                let want = if dtype == DataType::F {
                    f64::from(*a as f32)
                } else {
                    *a
                };
                assert!(a.is_nan() && b.is_nan() || want.to_bits() == b.to_bits());
            }
        }
    }

    /// A truncated or corrupt archive, a profile and an unknown format
    /// are refused with the file and the reason.
    #[test]
    fn bad_x3p_files_are_named_with_what_is_wrong() {
        let dir = tempfile::tempdir().unwrap();
        let scan = Scan::new(64, 64, 1e-6, 1e-6, vec![1e-6; 64 * 64]).unwrap();
        let path = dir.path().join("good.x3p");
        write(&path, &scan, DataType::D).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.path().join("cut.x3p");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let e = read(&cut).unwrap_err().to_string();
        assert!(
            e.contains("cut.x3p") && e.contains("corrupt or truncated"),
            "{e}"
        );
        let garbage = dir.path().join("noise.x3p");
        std::fs::write(&garbage, b"PK\x03\x04 not really a zip").unwrap();
        let e = read(&garbage).unwrap_err().to_string();
        assert!(e.contains("noise.x3p") && e.contains("corrupt"), "{e}");
        // A map of one row (written past `Scan::new`'s check) is a profile.
        let one_row = Scan {
            ny: 1,
            heights: vec![0.0; 64].into(),
            ..scan
        };
        let prf = dir.path().join("profile.x3p");
        write(&prf, &one_row, DataType::D).unwrap();
        let e = read(&prf).unwrap_err().to_string();
        assert!(
            e.contains("profile.x3p") && e.contains("1-D profile"),
            "{e}"
        );
        let e = super::super::read_scan(Path::new("scan.plu"), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("scan.plu")
                && e.contains("unknown scan format `.plu`")
                && e.contains(".x3p"),
            "{e}"
        );
    }
}
