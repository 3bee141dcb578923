//! A scratch folder per fuzzing process, in memory where there is one.

use std::path::PathBuf;
use std::sync::OnceLock;

/// The folder, made once; `setup` fills it the first time.
pub fn dir(setup: impl FnOnce(&PathBuf)) -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base = if std::path::Path::new("/dev/shm").is_dir() {
            PathBuf::from("/dev/shm")
        } else {
            std::env::temp_dir()
        };
        let dir = base.join(format!("tracelab-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("fuzz scratch folder");
        setup(&dir);
        dir
    })
}
