//! Where writers put the files that go beside the main output (MTL libraries, textures).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;

/// A destination for named side files: the OBJ writer's MTL library and texture PNGs.
///
/// [`DirSink`] writes real files into a folder; [`MemorySink`] keeps them in memory (for
/// tests, or to zip them up). A closure `FnMut(&str, &[u8]) -> std::io::Result<()>` is a
/// sink too, receiving each whole file at once.
pub trait FileSink {
    /// Writes the file `name` with the given contents: a plain file name, or
    /// `folder/file` for a file in a subfolder (the OBJ writer's
    /// [`texture_dir`](crate::obj::ObjOptions::texture_dir)).
    fn write_file(&mut self, name: &str, contents: &[u8]) -> std::io::Result<()>;

    /// Opens the file `name` for streaming writes. The default buffers the contents and
    /// hands them to [`write_file`](Self::write_file) when the returned writer is finished.
    fn create(&mut self, name: &str) -> std::io::Result<Box<dyn Write + '_>>
    where
        Self: Sized,
    {
        Ok(Box::new(Buffered {
            sink: self,
            name: name.to_string(),
            data: Vec::new(),
            done: false,
        }))
    }
}

impl<F> FileSink for F
where
    F: FnMut(&str, &[u8]) -> std::io::Result<()>,
{
    fn write_file(&mut self, name: &str, contents: &[u8]) -> std::io::Result<()> {
        self(name, contents)
    }
}

/// Collects into memory, hands over on `flush` (the writers always flush).
struct Buffered<'a, S: FileSink> {
    sink: &'a mut S,
    name: String,
    data: Vec<u8>,
    done: bool,
}

impl<S: FileSink> Write for Buffered<'_, S> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.data.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if !self.done {
            self.done = true;
            self.sink.write_file(&self.name, &self.data)?;
        }
        Ok(())
    }
}

/// Keeps side files in memory, by name in name order.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MemorySink {
    /// The files written so far.
    pub files: BTreeMap<String, Vec<u8>>,
}

impl MemorySink {
    /// An empty sink.
    pub fn new() -> Self {
        Self::default()
    }
}

impl FileSink for MemorySink {
    fn write_file(&mut self, name: &str, contents: &[u8]) -> std::io::Result<()> {
        self.files.insert(name.to_string(), contents.to_vec());
        Ok(())
    }
}

/// Writes side files into a folder (which must exist); a `folder/file` name creates the
/// subfolder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DirSink {
    /// The folder.
    pub dir: PathBuf,
}

impl DirSink {
    /// A sink writing into `dir`.
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        DirSink { dir: dir.into() }
    }

    /// The path of `name` (`file` or `folder/file`, plain names only), creating the
    /// subfolder.
    fn path(&self, name: &str) -> std::io::Result<PathBuf> {
        let bad = |part: &str| {
            part.is_empty() || part.contains(['/', '\\', ':']) || part == "." || part == ".."
        };
        let (folder, file) = match name.split_once('/') {
            Some((folder, file)) => (Some(folder), file),
            None => (None, name),
        };
        if bad(file) || folder.is_some_and(bad) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("{name:?} is not a plain file name or folder/file"),
            ));
        }
        let mut path = self.dir.clone();
        if let Some(folder) = folder {
            path.push(folder);
            std::fs::create_dir_all(&path)?;
        }
        Ok(path.join(file))
    }
}

impl FileSink for DirSink {
    fn write_file(&mut self, name: &str, contents: &[u8]) -> std::io::Result<()> {
        std::fs::write(self.path(name)?, contents)
    }

    fn create(&mut self, name: &str) -> std::io::Result<Box<dyn Write + '_>> {
        let file = std::fs::File::create(self.path(name)?)?;
        Ok(Box::new(std::io::BufWriter::new(file)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_and_closure_sinks() {
        let mut m = MemorySink::new();
        {
            let mut w = m.create("a.txt").unwrap();
            w.write_all(b"hello ").unwrap();
            w.write_all(b"world").unwrap();
            w.flush().unwrap();
        }
        m.write_file("b.bin", &[1, 2]).unwrap();
        assert_eq!(m.files["a.txt"], b"hello world");
        assert_eq!(m.files.len(), 2);

        let mut seen = Vec::new();
        let mut f = |name: &str, bytes: &[u8]| {
            seen.push((name.to_string(), bytes.len()));
            Ok(())
        };
        f.write_file("x", b"abc").unwrap();
        assert_eq!(seen, [("x".to_string(), 3)]);
    }

    #[test]
    fn dir_sink_rejects_paths() {
        let d = DirSink::new(std::env::temp_dir());
        assert!(d.path("../x").is_err());
        assert!(d.path("").is_err());
        assert!(d.path("ok.png").is_ok());
    }
}
