//! ParaView output: one VTK XML UnstructuredGrid (`.vtu`) per frame, and a `.pvd`
//! collection that lists every frame written so far with its time.
//!
//! Frames are written with vtkio's XML writer: inline base64 `binary` arrays with a
//! UInt64 size header, little-endian, uncompressed (file format version 1.0).
//! Both the frames and the collection are written to a temporary file and renamed,
//! so a run that stops at any moment leaves a loadable collection.

use super::atomic::write_atomically;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use super::text::f64_string;
use crate::dim::voigt;
use crate::model::particles::Particles;

/// Writer of ParaView frames `{prefix}_{NNNNN}.vtu` and the collection `{prefix}.pvd`.
///
/// Each frame is an UnstructuredGrid with one vertex cell per particle; points have three
/// coordinates (z = 0 in 2D). Point data: `velocity` (3), `displacement` x − X0 (3),
/// `stress` (6, Cauchy, in VTK's symmetric-tensor order xx, yy, zz, xy, yz, xz), `body`
/// and `material` (UInt32), `mass`, `volume`, `J` = det F, then the caller's extra scalars.
pub struct FrameWriter {
    dir: PathBuf,
    prefix: String,
    /// (time, file name relative to `dir`) of every frame written.
    frames: Vec<(f64, String)>,
}

impl FrameWriter {
    /// Prepare to write frames into `dir` (created if missing) with file names starting `prefix`.
    pub fn new(dir: &Path, prefix: &str) -> io::Result<Self> {
        fs::create_dir_all(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            prefix: prefix.to_string(),
            frames: Vec::new(),
        })
    }

    /// Write on after the `frames` (time, file name) an earlier run had written
    /// into `dir` (from a checkpoint): the numbering and the collection continue.
    pub fn resume(dir: &Path, prefix: &str, frames: Vec<(f64, String)>) -> io::Result<Self> {
        let mut w = Self::new(dir, prefix)?;
        w.frames = frames;
        if !w.frames.is_empty() {
            w.write_pvd()?;
        }
        Ok(w)
    }

    /// (time, file name) of every frame written so far.
    pub fn frames(&self) -> &[(f64, String)] {
        &self.frames
    }

    /// Write the next frame (time `t`) and rewrite the `.pvd` collection. Each `extra`
    /// entry is a named scalar point field with one value per particle.
    pub fn write_frame<const D: usize>(
        &mut self,
        t: f64,
        p: &Particles<D>,
        extra: &[(&str, &[f64])],
    ) -> io::Result<()> {
        let n = p.len();
        for (name, values) in extra {
            if values.len() != n {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "frame field {name:?} has {} values for {n} particles",
                        values.len()
                    ),
                ));
            }
        }
        let name = format!("{}_{:05}.vtu", self.prefix, self.frames.len());
        let vtk = frame_model(p, extra);
        write_atomically(&self.dir.join(&name), |w| {
            if n > 0 {
                return vtk.write_xml(w).map_err(io::Error::other);
            }
            // vtkio omits `NumberOfCells` when it is zero, and VTK then refuses the piece.
            let mut buf = Vec::new();
            vtk.write_xml(&mut buf).map_err(io::Error::other)?;
            let xml = String::from_utf8(buf).map_err(io::Error::other)?;
            let xml = xml.replacen(
                r#"<Piece NumberOfPoints="0""#,
                r#"<Piece NumberOfPoints="0" NumberOfCells="0""#,
                1,
            );
            w.write_all(xml.as_bytes())
        })?;
        self.frames.push((t, name));
        self.write_pvd()
    }

    /// Path of the `.pvd` collection file.
    pub fn pvd_path(&self) -> PathBuf {
        self.dir.join(format!("{}.pvd", self.prefix))
    }

    /// Number of frames written so far.
    pub fn frames_written(&self) -> usize {
        self.frames.len()
    }

    fn write_pvd(&self) -> io::Result<()> {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n\
             <VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  \
             <Collection>\n",
        );
        for (t, file) in &self.frames {
            s.push_str(&format!(
                "    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
                f64_string(*t),
                xml_escape(file)
            ));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        write_atomically(&self.pvd_path(), |w| w.write_all(s.as_bytes()))
    }
}

/// Build the vtkio model of one frame.
fn frame_model<const D: usize>(p: &Particles<D>, extra: &[(&str, &[f64])]) -> Vtk {
    let n = p.len();
    // Pad a D-vector to three components.
    let pad3 = |get: &dyn Fn(usize) -> f64| -> [f64; 3] {
        std::array::from_fn(|k| if k < D { get(k) } else { 0.0 })
    };
    let mut points = Vec::with_capacity(3 * n);
    let mut velocity = Vec::with_capacity(3 * n);
    let mut displacement = Vec::with_capacity(3 * n);
    let mut stress = Vec::with_capacity(6 * n);
    let mut jac = Vec::with_capacity(n);
    for i in 0..n {
        points.extend(pad3(&|k| p.x[i][k]));
        velocity.extend(pad3(&|k| p.v[i][k]));
        displacement.extend(pad3(&|k| p.x[i][k] - p.x0[i][k]));
        stress.extend(voigt(&p.stress.get(i)));
        jac.push(p.f.get(i).determinant());
    }

    let array = |name: &str, elem: ElementType, data: IOBuffer| {
        Attribute::DataArray(DataArray {
            name: name.to_string(),
            elem,
            data,
        })
    };
    let mut point = vec![
        array("velocity", ElementType::Vectors, velocity.into()),
        array("displacement", ElementType::Generic(3), displacement.into()),
        array("stress", ElementType::Generic(6), stress.into()),
        array("body", ElementType::Generic(1), p.body.clone().into()),
        array(
            "material",
            ElementType::Generic(1),
            p.material.clone().into(),
        ),
        array("mass", ElementType::Generic(1), p.mass.clone().into()),
        array("volume", ElementType::Generic(1), p.volume.clone().into()),
        array("J", ElementType::Generic(1), jac.into()),
    ];
    for (name, values) in extra {
        point.push(array(name, ElementType::Generic(1), values.to_vec().into()));
    }

    let cells = Cells {
        cell_verts: VertexNumbers::XML {
            connectivity: (0..n as u64).collect(),
            offsets: (1..=n as u64).collect(),
        },
        types: vec![CellType::Vertex; n],
    };
    Vtk {
        version: Version::new((1, 0)),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: points.into(),
            cells,
            data: Attributes {
                point,
                cell: Vec::new(),
            },
        }),
    }
}

/// Escape the five XML special characters for use in an attribute value.
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::{Mat3, Vector};
    use vtkio::model::Piece;

    /// Read a `.vtu` back with vtkio and return its single piece.
    fn read_piece(path: &Path) -> UnstructuredGridPiece {
        let vtk = Vtk::import(path).unwrap();
        match vtk.data {
            DataSet::UnstructuredGrid { pieces, .. } => {
                assert_eq!(pieces.len(), 1);
                match pieces.into_iter().next().unwrap() {
                    Piece::Inline(piece) => *piece,
                    other => panic!("expected an inline piece, got {other:?}"),
                }
            }
            other => panic!("expected an UnstructuredGrid, got {other:?}"),
        }
    }

    /// A named point field as f64 values, with its number of components.
    fn field(piece: &UnstructuredGridPiece, name: &str) -> (usize, Vec<f64>) {
        for a in &piece.data.point {
            if let Attribute::DataArray(d) = a {
                if d.name == name {
                    return (d.num_comp(), d.data.clone().cast_into::<f64>().unwrap());
                }
            }
        }
        panic!("no point field {name}");
    }

    fn scene_2d() -> Particles<2> {
        let mut p = Particles::<2>::default();
        let h = Vector::<2>::repeat(0.25);
        p.push(
            Vector::<2>::new(0.0, 0.0),
            Vector::<2>::new(1.0, 2.0),
            1.0,
            0.5,
            h,
            0,
            0,
            0,
        );
        p.push(
            Vector::<2>::new(1.0, 0.0),
            Vector::zeros(),
            2.0,
            0.5,
            h,
            1,
            3,
            0,
        );
        p.push(
            Vector::<2>::new(0.0, 1.0),
            Vector::zeros(),
            3.0,
            0.5,
            h,
            1,
            3,
            0,
        );
        p
    }

    #[test]
    fn two_frames_and_collection_2d() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("vtk");
        let mut fw = FrameWriter::new(&out, "frame").unwrap();
        let mut p = scene_2d();
        fw.write_frame(0.0, &p, &[]).unwrap();

        p.x[1] = Vector::<2>::new(1.25, -0.5);
        p.stress
            .set(1, &Mat3::new(1.0, 4.0, 0.0, 4.0, 2.0, 0.0, 0.0, 0.0, 3.0));
        p.f.set(
            1,
            &Mat3::from_diagonal(&nalgebra::Vector3::new(1.1, 0.9, 1.0)),
        );
        let plastic = [0.0, 0.125, 0.25];
        fw.write_frame(0.015625, &p, &[("plastic_strain", &plastic)])
            .unwrap();
        assert_eq!(fw.frames_written(), 2);

        // The collection lists both frames with their times.
        let pvd = std::fs::read_to_string(out.join("frame.pvd")).unwrap();
        assert!(pvd.contains(r#"type="Collection""#), "{pvd}");
        let sets: Vec<&str> = pvd.lines().filter(|l| l.contains("<DataSet")).collect();
        assert_eq!(sets.len(), 2, "{pvd}");
        assert!(sets[0].contains(r#"timestep="0""#), "{}", sets[0]);
        assert!(sets[0].contains(r#"file="frame_00000.vtu""#), "{}", sets[0]);
        assert!(sets[1].contains(r#"timestep="0.015625""#), "{}", sets[1]);
        assert!(sets[1].contains(r#"file="frame_00001.vtu""#), "{}", sets[1]);
        // No temporary files left behind.
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, ["frame.pvd", "frame_00000.vtu", "frame_00001.vtu"]);

        // First frame: unstressed, three vertex cells.
        let first = read_piece(&out.join("frame_00000.vtu"));
        assert_eq!(first.num_points(), 3);
        assert_eq!(first.cells.num_cells(), 3);
        assert!(first.cells.types.iter().all(|&c| c == CellType::Vertex));
        let (nc, s) = field(&first, "stress");
        assert_eq!(nc, 6);
        assert!(s.iter().all(|&x| x == 0.0));
        let (_, v) = field(&first, "velocity");
        assert_eq!(&v[..3], &[1.0, 2.0, 0.0]);

        // Second frame: moved, stressed, deformed particle 1 and the extra field.
        let second = read_piece(&out.join("frame_00001.vtu"));
        assert_eq!(second.num_points(), 3);
        let pts = second.points.clone().cast_into::<f64>().unwrap();
        assert_eq!(&pts[3..6], &[1.25, -0.5, 0.0]);
        let (_, s) = field(&second, "stress");
        assert_eq!(&s[6..12], &[1.0, 2.0, 3.0, 4.0, 0.0, 0.0]);
        let (nc, d) = field(&second, "displacement");
        assert_eq!(nc, 3);
        assert_eq!(&d[3..6], &[0.25, -0.5, 0.0]);
        let (_, j) = field(&second, "J");
        assert!((j[1] - 0.99).abs() < 1e-15 && j[0] == 1.0);
        let (_, body) = field(&second, "body");
        assert_eq!(body, [0.0, 1.0, 1.0]);
        let (_, material) = field(&second, "material");
        assert_eq!(material, [0.0, 3.0, 3.0]);
        let (_, mass) = field(&second, "mass");
        assert_eq!(mass, [1.0, 2.0, 3.0]);
        let (nc, ps) = field(&second, "plastic_strain");
        assert_eq!(nc, 1);
        assert_eq!(ps, plastic);
    }

    #[test]
    fn frame_3d_reads_back() {
        let mut p = Particles::<3>::default();
        let h = Vector::<3>::repeat(0.5);
        for k in 0..4 {
            let x = Vector::<3>::new(k as f64, 2.0 * k as f64, -(k as f64));
            p.push(x, Vector::<3>::new(0.0, 0.0, 1.0), 1.0, 1.0, h, 0, 0, 0);
        }
        p.stress.set(
            2,
            &Mat3::new(-1.0, 0.5, 0.25, 0.5, -2.0, 0.125, 0.25, 0.125, -3.0),
        );
        let dir = tempfile::tempdir().unwrap();
        let mut fw = FrameWriter::new(dir.path(), "run").unwrap();
        fw.write_frame(1.5, &p, &[]).unwrap();
        let piece = read_piece(&dir.path().join("run_00000.vtu"));
        assert_eq!(piece.num_points(), 4);
        let pts = piece.points.clone().cast_into::<f64>().unwrap();
        assert_eq!(&pts[9..12], &[3.0, 6.0, -3.0]);
        let (_, s) = field(&piece, "stress");
        assert_eq!(&s[12..18], &[-1.0, -2.0, -3.0, 0.5, 0.125, 0.25]);
        let (_, v) = field(&piece, "velocity");
        assert_eq!(&v[..3], &[0.0, 0.0, 1.0]);
        let pvd = std::fs::read_to_string(fw.pvd_path()).unwrap();
        assert!(pvd.contains(r#"timestep="1.5" group="" part="0" file="run_00000.vtu""#));
    }

    #[test]
    fn vtu_header_declares_encoding() {
        let dir = tempfile::tempdir().unwrap();
        let mut fw = FrameWriter::new(dir.path(), "f").unwrap();
        fw.write_frame(0.0, &scene_2d(), &[]).unwrap();
        let text = std::fs::read_to_string(dir.path().join("f_00000.vtu")).unwrap();
        assert!(text.starts_with(
            r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
        ), "{}", &text[..200.min(text.len())]);
        assert!(text.contains(r#"format="binary""#));
    }

    #[test]
    fn empty_particles_and_bad_extra() {
        let dir = tempfile::tempdir().unwrap();
        let mut fw = FrameWriter::new(dir.path(), "e").unwrap();
        fw.write_frame(0.0, &Particles::<2>::default(), &[])
            .unwrap();
        let path = dir.path().join("e_00000.vtu");
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(r#"NumberOfCells="0""#), "{text}");
        let piece = read_piece(&path);
        assert_eq!(piece.num_points(), 0);
        assert_eq!(piece.cells.num_cells(), 0);
        let short = [1.0];
        let err = fw
            .write_frame(1.0, &scene_2d(), &[("eps", &short)])
            .unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert_eq!(fw.frames_written(), 1);
    }

    #[test]
    fn escapes_xml() {
        assert_eq!(
            xml_escape(r#"a&b<"c">'"#),
            "a&amp;b&lt;&quot;c&quot;&gt;&apos;"
        );
    }
}
