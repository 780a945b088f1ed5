//! The unit tests of `sepval_common::telemetry`.

#![allow(clippy::float_cmp)]

use std::path::Path;

use sepval_common::telemetry::*;

const GOOD: &str = "# event = drop 1\n# mach: 0.95\n# free text\n\
    t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n\
    0,0,0,0,0,0,0\n0.005,0.1,0.2,0.3,1,2,3\n";

fn err(text: &str) -> String {
    Trajectory::parse(text, "f.csv").unwrap_err().to_string()
}

#[test]
fn reads_metadata_and_samples() {
    let t = Trajectory::parse(GOOD, "f.csv").unwrap();
    assert_eq!(t.len(), 2);
    assert_eq!(t.meta("event"), Some("drop 1"));
    assert_eq!(t.meta("mach"), Some("0.95"));
    assert_eq!(t.comments.len(), 3);
    assert_eq!(t.pos_m[1], [0.1, 0.2, 0.3]);
    assert_eq!(t.att_deg[1], [1.0, 2.0, 3.0]);
}

#[test]
fn a_metadata_key_given_twice_must_keep_its_value() {
    // Another value: refused, naming both lines (`#` and `:` forms alike).
    let twice = format!("# mach = 1.2\n# free: text\n# mach: 0.6\n{}", &GOOD[42..]);
    assert_eq!(
        err(&twice),
        "f.csv: line 3: metadata `mach` is given twice with different values: `0.6` here, `1.2` at line 1; give it once"
    );
    // The same value again: accepted, one value.
    let same = format!("# mach = 0.95\n{GOOD}");
    let t = Trajectory::parse(&same, "f.csv").unwrap();
    assert_eq!(t.meta("mach"), Some("0.95"));
    assert_eq!(t.metadata.len(), 3);
}

#[test]
fn feet_are_converted_and_columns_may_be_reordered() {
    let text = "yaw_deg,t_s,x_ft,y_ft,z_ft,roll_deg,pitch_deg,mach\n3,0.5,1,2,10,1,2,0.9\n";
    let t = Trajectory::parse(text, "f.csv").unwrap();
    assert_eq!(t.times_s, vec![0.5]);
    assert_eq!(t.pos_m[0], [0.3048, 2.0 * 0.3048, 10.0 * 0.3048]);
    assert_eq!(t.att_deg[0], [1.0, 2.0, 3.0]);
}

#[test]
fn write_read_round_trip_is_exact() {
    let mut t = Trajectory::parse(GOOD, "f.csv").unwrap();
    t.pos_m[1] = [0.1 + 0.2, -1.0 / 3.0, 5.780992554123456];
    t.att_deg[1] = [26.094_358_812_345_68, -1e-300, 179.999_999_999_999_97];
    let back = Trajectory::parse(&t.to_csv_string(), "g.csv").unwrap();
    assert_eq!(back, t);
}

#[test]
fn every_bad_input_names_file_line_and_column() {
    assert_eq!(
        err(""),
        "f.csv: empty file: expected a header row `t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg`"
    );
    assert_eq!(err("# only a comment\n\n"), err(""));
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n"),
        "f.csv: no samples after the header (line 1)"
    );
    assert_eq!(
        err("t_s,x_m,y_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0\n"),
        "f.csv: line 1: missing column for z: expected `z_m` or `z_ft`"
    );
    assert_eq!(
        err("t_s,x_km,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n"),
        "f.csv: line 1, column 2: unknown unit in `x_km`: expected `x_m` or `x_ft`"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_rad,pitch_deg,yaw_deg\n"),
        "f.csv: line 1, column 5: unknown unit in `roll_rad`: expected `roll_deg`"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,x_ft\n"),
        "f.csv: line 1, column 8: `x_ft` repeats the x column"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0\n"),
        "f.csv: line 2: expected 7 fields as in the header, found 6"
    );
    assert_eq!(
        err("# c\nt_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,abc,0,0,0\n"),
        "f.csv: line 3, column 4 (`z_m`): expected a number, found `abc`"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,NaN,0\n"),
        "f.csv: line 2, column 6 (`pitch_deg`): expected a finite number, found `NaN`"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,inf\n"),
        "f.csv: line 2, column 7 (`yaw_deg`): expected a finite number, found `inf`"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0.1,0,0,0,0,0,0\n0.1,0,0,0,0,0,0\n"),
        "f.csv: line 3, column 1 (`t_s`): time 0.1 s is not after the previous sample's 0.1 s (times must increase strictly)"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,\n"),
        "f.csv: line 2, column 7 (`yaw_deg`): expected a number, found ``"
    );
}

#[test]
fn unreadable_file_is_named() {
    let e = Trajectory::read(Path::new("/no/such/file.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("/no/such/file.csv: cannot read:"), "{e}");
}

#[test]
fn spreadsheet_exports_read_and_implausible_values_are_refused_where_they_stand() {
    let bom = format!("\u{feff}{GOOD}");
    assert_eq!(Trajectory::parse(&bom, "f.csv").unwrap().len(), 2);
    let quoted = "\"t_s\",\"x_m\",\"y_m\",\"z_m\",\"roll_deg\",\"pitch_deg\",\"yaw_deg\"\r\n\"0\",0,0,0,0,0,0\r\n";
    assert_eq!(Trajectory::parse(quoted, "f.csv").unwrap().len(), 1);
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,\"0,0,0,0,0\n"),
        "f.csv: line 2, column 3: unbalanced double quote in `\"0` (a quoted field must start and end with a quote)"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,1e308,0,0,0,0,0\n"),
        "f.csv: line 2, column 2 (`x_m`): 1e308 is beyond the plausible bound of +-100000 m for a position"
    );
    assert_eq!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n1e6,0,0,0,0,0,0\n"),
        "f.csv: line 2, column 1 (`t_s`): 1e6 is beyond the plausible bound of +-3600 s for a sample time"
    );
    assert!(
        err("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,4000\n")
            .contains("for an angle")
    );
    let lines = GOOD.split('\n').map(|l| Ok(l.as_bytes().to_vec()));
    assert_eq!(
        Trajectory::parse_lines(lines, "f.csv", 1)
            .unwrap_err()
            .to_string(),
        "f.csv: line 6: more than 1 samples, the limit per event"
    );
    let bad_utf8 = [
        b"t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg".to_vec(),
        vec![0xff, 0xfe],
    ];
    assert_eq!(
        Trajectory::parse_lines(bad_utf8.into_iter().map(Ok), "f.csv", 10)
            .unwrap_err()
            .to_string(),
        "f.csv: line 2: not valid UTF-8 text"
    );
}
