//! Tests of `tapsim::app::report::output` (src/app/report/output.rs).

use std::fs;
use std::path::PathBuf;
use tapsim::app::report::output::*;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tapsim-output-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_symlink_is_followed_and_kept() {
    let dir = scratch("link");
    fs::write(dir.join("real.csv"), "old").unwrap();
    std::os::unix::fs::symlink("real.csv", dir.join("link.csv")).unwrap();
    write_bytes(&dir.join("link.csv"), b"new").unwrap();
    assert!(
        fs::symlink_metadata(dir.join("link.csv"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(fs::read_to_string(dir.join("real.csv")).unwrap(), "new");
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_failed_write_leaves_nothing_and_names_the_users_path() {
    let dir = scratch("fail");
    let path = dir.join("out.png");
    let e = write_with(&path, |tmp| {
        fs::write(tmp, "half").unwrap();
        Err(io(tmp, std::io::Error::other("disk on fire")))
    })
    .unwrap_err()
    .to_string();
    assert!(e.contains("out.png") && !e.contains("partial"), "{e}");
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 0);
    assert!(partial_files().is_empty());
    fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_missing_directory_is_refused_not_created() {
    let dir = scratch("missing");
    let e = write_bytes(&dir.join("no/such/x.csv"), b"x")
        .unwrap_err()
        .to_string();
    assert!(e.contains("does not exist"), "{e}");
    assert!(!dir.join("no").exists());
    let e = write_bytes(&dir, b"x").unwrap_err().to_string();
    assert!(e.contains("directory"), "{e}");
    fs::remove_dir_all(dir).unwrap();
}
