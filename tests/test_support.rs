//! The shared test helpers themselves: when golden images are blessed, and what a test does
//! when the reference corpus is absent.

mod common;

use std::path::PathBuf;

use common::{bless_value, refdata_in};

#[test]
fn bless_only_when_asked() {
    use std::ffi::OsStr;
    for (v, want) in [
        (None, false),
        (Some("0"), false),
        (Some(""), false),
        (Some("no"), false),
        (Some("1"), true),
        (Some("true"), true),
        (Some("TRUE"), true),
    ] {
        assert_eq!(bless_value(v.map(OsStr::new)), want, "ORBCLOUD_BLESS={v:?}");
    }
}

#[test]
fn missing_refdata_skips_unless_required() {
    let absent = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/no-such-corpus");
    assert_eq!(refdata_in("t", absent.clone(), false), None);
    let present = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests");
    assert_eq!(refdata_in("t", present.clone(), true), Some(present));
    let failed = std::panic::catch_unwind(|| refdata_in("t", absent, true));
    assert!(failed.is_err(), "a required corpus that is absent must fail");
}
