//! Raw CAN of the comma2k19 segment decoded with the built-in DBC subset and
//! mapping: equal to the processed streams sample for sample.

mod common;

use std::path::Path;

use deadreckon_core::drive::Wheels;
use deadreckon_import::can::{
    decode_frames, read_raw_can, Database, Mapping, TOYOTA_RAV4_DBC, TOYOTA_RAV4_MAP,
};
use deadreckon_import::comma2k19::{read_comma2k19_with, Comma2k19Options, SpeedSource};
use deadreckon_import::{profiles, TimeOrderPolicy};

#[test]
fn decoded_wheel_speeds_and_steering_equal_the_processed_ones() {
    let seg = common::data("comma2k19-rav4");
    let frames = read_raw_can(&seg.join("processed_log/CAN/raw_can")).unwrap();
    assert_eq!(frames.len(), 135_468);
    let db = Database::parse(TOYOTA_RAV4_DBC, Path::new("toyota_rav4_subset.dbc")).unwrap();
    let map = Mapping::parse(
        TOYOTA_RAV4_MAP,
        &db,
        Path::new("toyota_rav4_comma2k19.toml"),
    )
    .unwrap();
    let can = decode_frames(
        &frames,
        &map,
        profiles::toyota_rav4(),
        TimeOrderPolicy::Error,
        &seg,
    )
    .unwrap();
    println!("{}", can.report);
    let o = Comma2k19Options {
        speed: SpeedSource::Processed,
        ..Default::default()
    };
    let processed = read_comma2k19_with(&seg, &o).unwrap().drive;

    let (Wheels::Speeds(a), Wheels::Speeds(b)) = (&can.drive.wheels, &processed.wheels) else {
        panic!()
    };
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(x.t_s, y.t_s);
        for (u, v) in [
            (x.fl_mps, y.fl_mps),
            (x.fr_mps, y.fr_mps),
            (x.rl_mps, y.rl_mps),
            (x.rr_mps, y.rr_mps),
        ] {
            assert!(
                (u - v).abs() < 1e-9,
                "t={}: decoded {u} processed {v}",
                x.t_s
            );
        }
    }
    assert_eq!(can.drive.steering.len(), processed.steering.len());
    for (x, y) in can.drive.steering.iter().zip(&processed.steering) {
        assert_eq!(x.t_s, y.t_s);
        assert!(
            (x.value - y.value).abs() < 1e-9,
            "t={}: decoded {} processed {}",
            x.t_s,
            x.value,
            y.value
        );
    }
    // SPEED (0xB4) decoded through the mapping equals the comma2k19 reader's default speed stream.
    let default = read_comma2k19_with(&seg, &Comma2k19Options::default())
        .unwrap()
        .drive;
    assert_eq!(can.drive.speed.len(), default.speed.len());
    for (x, y) in can.drive.speed.iter().zip(&default.speed) {
        assert_eq!(x.t_s, y.t_s);
        assert!((x.value - y.value).abs() < 1e-12);
    }
}

#[test]
fn candump_text_of_the_segment_decodes_like_the_arrays() {
    // The raw_can frames written as a candump log and parsed back decode to the same streams.
    let seg = common::data("comma2k19-rav4");
    let frames = read_raw_can(&seg.join("processed_log/CAN/raw_can")).unwrap();
    let text: String = frames
        .iter()
        .map(|f| {
            let hex: String = f.data.iter().map(|b| format!("{b:02X}")).collect();
            let id = if f.extended {
                format!("{:08X}", f.id)
            } else {
                format!("{:03X}", f.id)
            };
            format!("({:.9}) {} {id}#{hex}\n", f.t_s, f.bus)
        })
        .collect();
    let parsed =
        deadreckon_import::can::parse_candump(text.as_bytes(), Path::new("segment.log")).unwrap();
    assert_eq!(parsed.len(), frames.len());
    let db = Database::parse(TOYOTA_RAV4_DBC, Path::new("toyota_rav4_subset.dbc")).unwrap();
    let map = Mapping::parse(
        TOYOTA_RAV4_MAP,
        &db,
        Path::new("toyota_rav4_comma2k19.toml"),
    )
    .unwrap();
    let v = profiles::toyota_rav4();
    let a = decode_frames(&frames, &map, v.clone(), TimeOrderPolicy::Error, &seg)
        .unwrap()
        .drive;
    let b = decode_frames(
        &parsed,
        &map,
        v,
        TimeOrderPolicy::Error,
        Path::new("segment.log"),
    )
    .unwrap()
    .drive;
    let (Wheels::Speeds(wa), Wheels::Speeds(wb)) = (&a.wheels, &b.wheels) else {
        panic!()
    };
    assert_eq!(wa.len(), wb.len());
    for (x, y) in wa.iter().zip(wb) {
        assert!((x.t_s - y.t_s).abs() < 1e-8);
        assert_eq!(
            (x.fl_mps, x.fr_mps, x.rl_mps, x.rr_mps),
            (y.fl_mps, y.fr_mps, y.rl_mps, y.rr_mps)
        );
    }
    assert_eq!(
        a.steering.iter().map(|s| s.value).collect::<Vec<_>>(),
        b.steering.iter().map(|s| s.value).collect::<Vec<_>>()
    );
}

/// Issue 12: `import can` on a comma2k19 segment directory failed with
/// "…/t: No such file or directory" instead of naming the raw_can folder.
#[test]
fn import_can_of_a_segment_directory_did_not_say_it_wants_raw_can() {
    let seg = common::data("comma2k19-rav4");
    for given in [seg.clone(), seg.join("processed_log")] {
        let e = read_raw_can(&given).unwrap_err().to_string();
        assert!(
            e.contains("not a raw_can folder")
                && e.contains("CAN/raw_can")
                && e.contains("import comma2k19"),
            "{e}"
        );
    }
}
