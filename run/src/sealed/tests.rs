use super::*;
use serde::Deserialize;

#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct Small {
    format: String,
    sigma_pos_m: f64,
    sigma_att_deg: f64,
}

impl Record for Small {
    const FORMAT: &'static str = "small/1";
    const COMMAND: &'static str = "small";
    fn check(&self) -> Result<(), FieldError> {
        check_noise(self.sigma_pos_m, self.sigma_att_deg)
    }
}

fn small() -> Small {
    Small {
        format: "small/1".into(),
        sigma_pos_m: 0.005,
        sigma_att_deg: 0.1,
    }
}

fn read(text: &str) -> Result<Small, RecordError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.json");
    std::fs::write(&path, text).unwrap();
    read_record(&path, "record")
}

#[test]
fn a_sealed_record_reads_back_whatever_its_spelling() {
    let text = String::from_utf8(sealed(&small())).unwrap();
    assert!(text.trim_end().ends_with('}'));
    assert_eq!(read(&text).unwrap(), small());
    // Another spelling of the same values, another order of keys: the same record.
    let value: Value = serde_json::from_str(&text).unwrap();
    let respelled = text.replace("0.005", "5e-3").replace("  ", "");
    assert_eq!(read(&respelled).unwrap(), small());
    assert_eq!(
        read(&serde_json::to_string(&value).unwrap()).unwrap(),
        small()
    );
}

#[test]
fn an_edit_a_missing_digest_and_bad_json_are_refused_by_name() {
    let text = String::from_utf8(sealed(&small())).unwrap();
    let e = read(&text.replace("0.005", "0.006"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("does not match its digest"), "{e}");
    let mut value: Value = serde_json::from_str(&text).unwrap();
    value.as_object_mut().unwrap().remove(DIGEST_KEY);
    let e = read(&value.to_string()).unwrap_err().to_string();
    assert!(e.contains("records no digest"), "{e}");
    let e = read("").unwrap_err().to_string();
    assert!(
        e.contains("line 1, column 0: not JSON: EOF while parsing"),
        "{e}"
    );
    let e = read("{\"format\": \"small/1\",\n \"sigma_pos_m\": NaN}")
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 2, column 17: not JSON"), "{e}");
    let e = read("{\"format\": \"other/3\"}").unwrap_err().to_string();
    assert!(e.contains("format other/3, expected small/1"), "{e}");
}

#[test]
fn a_sealed_value_out_of_range_is_refused_naming_the_field() {
    let mut s = small();
    s.sigma_att_deg = -1.0;
    let e = read(&String::from_utf8(sealed(&s)).unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`sigma_att_deg` = -1: expected an attitude noise in (0, 3600] deg"),
        "{e}"
    );
    s.sigma_att_deg = 0.1;
    s.sigma_pos_m = 1e300;
    let e = read(&String::from_utf8(sealed(&s)).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("`sigma_pos_m` = 1e300"), "{e}");
}
