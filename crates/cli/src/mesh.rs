//! `features mesh`: triangulates every solid of a STEP file into one binary STL or OBJ file.

use crate::{emit, Failure, MeshArgs};
use brep::mesh::MeshOptions;
use brep::solid::mesh_solid;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Output file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Stl,
    Obj,
}

impl Format {
    fn from_path(p: &Path) -> Option<Format> {
        let ext = p.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(Format::Stl),
            "obj" => Some(Format::Obj),
            _ => None,
        }
    }
}

/// One solid's triangles over its own compact vertex list (only vertices that triangles use).
pub(crate) struct SolidMesh {
    step_id: u64,
    positions: Vec<[f64; 3]>,
    pub(crate) triangles: Vec<[u32; 3]>,
    watertight: bool,
}

pub(crate) fn solid_mesh(step_id: u64, mesh: &brep::mesh::Mesh) -> SolidMesh {
    let (open, bad) = mesh.open_edges();
    let mut remap = vec![u32::MAX; mesh.positions.len()];
    let mut positions = vec![];
    let mut triangles = vec![];
    for t in mesh.triangles() {
        let mut g = [0u32; 3];
        for (k, &v) in t.iter().enumerate() {
            let r = &mut remap[v as usize];
            if *r == u32::MAX {
                *r = positions.len() as u32;
                let p = mesh.positions[v as usize];
                positions.push([p.x, p.y, p.z]);
            }
            g[k] = *r;
        }
        triangles.push(g);
    }
    SolidMesh {
        step_id,
        positions,
        triangles,
        watertight: open + bad == 0,
    }
}

/// A file being written under a temporary name beside its destination. Removed when dropped
/// (failure or panic) unless [`TempFile::persist`] renamed it into place.
pub(crate) struct TempFile {
    tmp: PathBuf,
    done: bool,
}

impl TempFile {
    pub(crate) fn create(dest: &Path) -> std::io::Result<(TempFile, File)> {
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "mesh".into());
        let tmp = dest.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        Ok((TempFile { tmp, done: false }, file))
    }

    /// Where it is being written.
    pub(crate) fn path(&self) -> &Path {
        &self.tmp
    }

    pub(crate) fn persist(mut self, dest: &Path) -> std::io::Result<()> {
        std::fs::rename(&self.tmp, dest)?;
        self.done = true;
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `dest` whole or not at all: `body` writes a temporary file beside it, which is
/// synced and renamed into place only when `body` succeeded.
pub(crate) fn write_atomic(
    dest: &Path,
    body: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let (tmp, file) = TempFile::create(dest)?;
    let mut w = std::io::BufWriter::new(file);
    body(&mut w)?;
    w.flush()?;
    w.get_ref().sync_all()?;
    drop(w);
    tmp.persist(dest)
}

/// Runs the command.
pub fn run(args: &MeshArgs) -> Result<(), Failure> {
    let start = Instant::now();
    let (input, output) = (&args.part, &args.output);
    let format = Format::from_path(output).ok_or_else(|| {
        Failure::new(
            output,
            "unknown output format: the file name must end in .stl or .obj",
        )
    })?;
    let part = brep::read_step(input).map_err(|e| Failure::new(input, e))?;
    let brep = &part.brep;
    let opts = MeshOptions::with_tolerance(args.tolerance);
    let mut solids = vec![];
    for s in brep.solid_ids() {
        let id = brep.solids[s.idx()].step_id;
        let m = mesh_solid(brep, s, Some(opts))
            .map_err(|e| Failure::new(input, format!("solid #{id}: {e}")))?;
        solids.push(solid_mesh(id, &m));
    }
    let triangles: usize = solids.iter().map(|m| m.triangles.len()).sum();
    let vertices: usize = solids.iter().map(|m| m.positions.len()).sum();
    if format == Format::Stl && u32::try_from(triangles).is_err() {
        return Err(Failure::new(
            output,
            format!("{triangles} triangles are too many for STL"),
        ));
    }

    let write_err = |e: std::io::Error| Failure::new(output, format!("cannot write: {e}"));
    let (tmp, file) = TempFile::create(output).map_err(write_err)?;
    let mut w = BufWriter::new(file);
    let source = input.display().to_string();
    match format {
        Format::Stl => write_stl(&mut w, &source, &solids, triangles as u32),
        Format::Obj => write_obj(&mut w, &source, &solids),
    }
    .map_err(write_err)?;
    let file = w.into_inner().map_err(|e| write_err(e.into_error()))?;
    file.sync_all().map_err(write_err)?;
    drop(file);
    tmp.persist(output).map_err(write_err)?;

    let watertight = solids.iter().all(|m| m.watertight);
    emit(&format!(
        "{} -> {}: {} solid{}, {triangles} triangles, {vertices} vertices, watertight: {}, {:.2} s\n",
        source,
        output.display(),
        solids.len(),
        if solids.len() == 1 { "" } else { "s" },
        if watertight { "yes" } else { "no" },
        start.elapsed().as_secs_f64()
    ))
}

/// Binary STL: 80-byte header naming the source, triangle count, then per triangle the unit
/// normal (from the vertices, right-handed) and the three vertices as little-endian `f32`.
pub(crate) fn write_stl(
    w: &mut impl Write,
    source: &str,
    solids: &[SolidMesh],
    n: u32,
) -> std::io::Result<()> {
    let text: String = format!("features mesh of {source}")
        .chars()
        .map(|c| {
            if c.is_ascii() && !c.is_ascii_control() {
                c
            } else {
                '?'
            }
        })
        .collect();
    let mut header = [b' '; 80];
    let len = text.len().min(80);
    header[..len].copy_from_slice(&text.as_bytes()[..len]);
    w.write_all(&header)?;
    w.write_all(&n.to_le_bytes())?;
    for m in solids {
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let nrm = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
            let nrm = if len > 0.0 {
                nrm.map(|x| x / len)
            } else {
                [0.0; 3]
            };
            let mut rec = [0u8; 50];
            for (k, x) in nrm.iter().chain(&a).chain(&b).chain(&c).enumerate() {
                rec[4 * k..4 * k + 4].copy_from_slice(&(*x as f32).to_le_bytes());
            }
            w.write_all(&rec)?;
        }
    }
    Ok(())
}

/// Wavefront OBJ: one `o solid_<n>` group per solid (1-based, file order), `v` lines in mm,
/// `f` lines with 1-based indices counted over the whole file.
fn write_obj(w: &mut impl Write, source: &str, solids: &[SolidMesh]) -> std::io::Result<()> {
    writeln!(
        w,
        "# features mesh of {}",
        source.replace(['\n', '\r'], " ")
    )?;
    writeln!(w, "# units: mm; {} solid(s)", solids.len())?;
    let mut base = 1usize;
    for (i, m) in solids.iter().enumerate() {
        writeln!(w, "o solid_{}", i + 1)?;
        writeln!(w, "# STEP #{}", m.step_id)?;
        for p in &m.positions {
            writeln!(w, "v {} {} {}", fmt(p[0]), fmt(p[1]), fmt(p[2]))?;
        }
        for t in &m.triangles {
            writeln!(
                w,
                "f {} {} {}",
                base + t[0] as usize,
                base + t[1] as usize,
                base + t[2] as usize
            )?;
        }
        base += m.positions.len();
    }
    Ok(())
}

/// A coordinate with up to 6 decimals (1 nm), trailing zeros dropped, no exponent, no `-0`.
fn fmt(x: f64) -> String {
    let s = format!("{:.6}", x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}
