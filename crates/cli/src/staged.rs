//! The machine program's files as the post writes them ([`plan::plan_into`]), and
//! `toolpath.csv` as it is written beside them: each under a temporary name in the output
//! folder, renamed into place only when the whole plan passed its checks
//! ([`Staged::commit`]), removed otherwise (dropped uncommitted), with the folders made for
//! them. So a program of hundreds of megabytes is never held in memory,
//! and a failed plan still leaves nothing that looks complete.

use crate::mesh::TempFile;
use crate::outputs::Outputs;
use robot_post::ProgramSink;
use std::fs::File;
use std::io::Write;

/// Bytes each file's writer gathers before a write.
const BUFFER: usize = 1 << 20;

/// The program's files written so far, not yet in place.
pub(crate) struct Staged<'a> {
    outputs: &'a Outputs,
    /// The folders made for these files (the output folder and those of its parents that did
    /// not exist), innermost first.
    made_dirs: Vec<std::path::PathBuf>,
    /// Each file's name in the folder and its temporary file.
    files: Vec<(String, TempFile)>,
}

impl<'a> Staged<'a> {
    /// Nothing written yet into `outputs`' folder.
    pub(crate) fn new(outputs: &'a Outputs) -> Staged<'a> {
        Staged {
            outputs,
            made_dirs: vec![],
            files: vec![],
        }
    }

    /// The files' names in the output folder, in the order written.
    pub(crate) fn names(&self) -> Vec<String> {
        self.files.iter().map(|(n, _)| n.clone()).collect()
    }

    /// Syncs every file and renames it into place.
    pub(crate) fn commit(mut self) -> std::io::Result<()> {
        for (name, tmp) in std::mem::take(&mut self.files) {
            let dest = self.outputs.dir.join(&name);
            std::fs::File::open(tmp.path())?.sync_all()?;
            tmp.persist(&dest)?;
        }
        self.made_dirs.clear();
        Ok(())
    }
}

impl Staged<'_> {
    /// A writer for the output `name` (a name without a folder, the `-o` stem put before it
    /// as for every output), staged like the program's files.
    pub(crate) fn open(&mut self, name: &str) -> std::io::Result<std::io::BufWriter<File>> {
        let dir = &self.outputs.dir;
        if !dir.is_dir() {
            // The folders about to be made: the output folder and its missing parents.
            let missing: Vec<_> = dir
                .ancestors()
                .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
                .map(|d| d.to_path_buf())
                .collect();
            std::fs::create_dir_all(dir)?;
            self.made_dirs = missing;
        }
        let name = self.outputs.name(name);
        let (tmp, file) = TempFile::create(&dir.join(&name))?;
        self.files.push((name, tmp));
        Ok(std::io::BufWriter::with_capacity(BUFFER, file))
    }
}

impl ProgramSink for Staged<'_> {
    fn file(&mut self, name: &str) -> std::io::Result<Box<dyn Write + '_>> {
        Ok(Box::new(self.open(name)?))
    }
}

impl Drop for Staged<'_> {
    fn drop(&mut self) {
        // The temporary files go first (each removes itself), then the folders made for them.
        self.files.clear();
        for d in &self.made_dirs {
            if std::fs::remove_dir(d).is_err() {
                break;
            }
        }
    }
}

/// The plan's program and `toolpath.csv`, staged afresh for each placement the plan tries
/// ([`plan::Outputs`]): a refused attempt's files are dropped (removed) when the next begins,
/// so only the chosen plan's are left to commit.
pub(crate) struct Fresh<'a> {
    outputs: &'a Outputs,
    staged: Option<Staged<'a>>,
    csv: Option<std::io::BufWriter<File>>,
}

impl<'a> Fresh<'a> {
    /// Nothing staged yet into `outputs`' folder.
    pub(crate) fn new(outputs: &'a Outputs) -> Fresh<'a> {
        Fresh {
            outputs,
            staged: None,
            csv: None,
        }
    }

    /// The last attempt's staged files, `toolpath.csv` closed; `None` when none began.
    pub(crate) fn last(mut self) -> Option<Staged<'a>> {
        self.csv = None;
        self.staged.take()
    }
}

impl plan::Outputs for Fresh<'_> {
    fn fresh(
        &mut self,
    ) -> std::io::Result<(&mut dyn ProgramSink, Option<&mut (dyn Write + Send)>)> {
        // The earlier attempt's writer first (its file), then its files.
        self.csv = None;
        self.staged = None;
        let mut staged = Staged::new(self.outputs);
        let csv = staged.open("toolpath.csv")?;
        let staged = self.staged.insert(staged);
        let csv = self.csv.insert(csv);
        Ok((staged, Some(csv)))
    }
}
