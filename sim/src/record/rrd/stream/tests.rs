//! Rows, chunks and reuse of the columns, read back from an in-memory recording.

use super::*;
use re_chunk::Chunk;
use rerun::ComponentDescriptor;
use rerun::external::arrow;
use rerun::external::arrow::array::Array;
use rerun::log::LogMsg;

/// (entity, rows, timelines) of every data chunk of `msgs`, in order.
fn chunks(msgs: &[LogMsg]) -> Vec<(String, usize, Vec<String>)> {
    msgs.iter()
        .filter_map(|m| match m {
            LogMsg::ArrowMsg(_, a) => Some(Chunk::from_arrow_msg(a).unwrap()),
            _ => None,
        })
        .filter(|c| !c.entity_path().to_string().starts_with("/__"))
        .map(|c| {
            let mut t: Vec<String> = c.timelines().keys().map(|k| k.to_string()).collect();
            t.sort();
            (c.entity_path().to_string(), c.num_rows(), t)
        })
        .collect()
}

/// The data chunks of entity `path` in `msgs`.
fn entity_chunks(msgs: &[LogMsg], path: &str) -> Vec<Chunk> {
    msgs.iter()
        .filter_map(|m| match m {
            LogMsg::ArrowMsg(_, a) => Chunk::from_arrow_msg(a).ok(),
            _ => None,
        })
        .filter(|c| c.entity_path().to_string() == path)
        .collect()
}

#[test]
fn plain_values_give_the_columns_of_the_archetypes() {
    use rerun::components::{Color, LineStrip3D, Position3D, Radius, Text};
    let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
    let mut s = RrdStream::new(rec);
    let c = Color::from_rgb(1, 2, 3);
    for k in 0..5 {
        let x = k as f32;
        s.set_duration_secs("sim_time", 0.5 * k as f64);
        // the same rows as archetypes ...
        s.log(
            "arch",
            &rerun::Points3D::new([[x, 1.0, 0.0], [x, 2.0, 0.0]])
                .with_radii([0.3])
                .with_colors([c])
                .with_labels([format!("p{k}")]),
        )
        .unwrap();
        // ... and as plain values
        s.row("plain")
            .with(
                rerun::Points3D::descriptor_positions(),
                [Position3D::new(x, 1.0, 0.0), Position3D::new(x, 2.0, 0.0)],
            )
            .with(rerun::Points3D::descriptor_radii(), [Radius::from(0.3)])
            .with(rerun::Points3D::descriptor_colors(), [c])
            .with(
                rerun::Points3D::descriptor_labels(),
                [Text::from(format!("p{k}"))],
            );
        // every other row without the strip: a null there, not an empty list
        if k % 2 == 0 {
            s.log(
                "arch",
                &rerun::LineStrips3D::new([[[x, 0.0, 0.0], [0.0, x, 0.0]]]),
            )
            .unwrap();
            s.row("plain").with(
                rerun::LineStrips3D::descriptor_strips(),
                [LineStrip3D::from([[x, 0.0, 0.0], [0.0, x, 0.0]])],
            );
        }
    }
    s.flush_blocking().unwrap();
    let msgs = storage.take();
    let (arch, plain) = (
        entity_chunks(&msgs, "/arch"),
        entity_chunks(&msgs, "/plain"),
    );
    assert_eq!((arch.len(), plain.len()), (1, 1));
    let (a, p) = (&arch[0], &plain[0]);
    assert_eq!((a.num_rows(), p.num_rows()), (8, 8));
    assert_eq!(
        a.timelines()[&"sim_time".into()].times_raw(),
        p.timelines()[&"sim_time".into()].times_raw()
    );
    let mut descriptors: Vec<_> = p.components().component_descriptors().cloned().collect();
    descriptors.sort_by_key(|d| d.to_string());
    let mut expected: Vec<_> = a.components().component_descriptors().cloned().collect();
    expected.sort_by_key(|d| d.to_string());
    assert_eq!(descriptors, expected);
    for d in &descriptors {
        let (x, y) = (
            a.components().get_array(d.component).unwrap(),
            p.components().get_array(d.component).unwrap(),
        );
        assert_eq!(x.to_data(), y.to_data(), "{d}");
    }
}

#[test]
fn a_component_given_twice_or_with_another_type_is_reported_and_left_out() {
    use rerun::components::{Radius, Scalar};
    let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
    let mut s = RrdStream::new(rec);
    s.row("x")
        .with(rerun::Scalars::descriptor_scalars(), [Scalar::from(1.0)])
        .with(rerun::Scalars::descriptor_scalars(), [Scalar::from(2.0)]);
    s.row("x")
        .with(rerun::Scalars::descriptor_scalars(), [Radius::from(3.0)]);
    let e = s.flush_blocking().unwrap_err();
    assert!(e.contains("/x") && e.contains("twice in one row"), "{e}");
    let msgs = storage.take();
    let chunk = &entity_chunks(&msgs, "/x")[0];
    let values = chunk
        .components()
        .get_array(rerun::Scalars::descriptor_scalars().component)
        .unwrap();
    // the first value of the first row; the second row has none
    assert_eq!(
        (values.len(), values.value_length(0), values.is_null(1)),
        (2, 1, true)
    );
    // the type mismatch alone is reported too
    let (rec, _storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
    let mut s = RrdStream::new(rec);
    s.row("x")
        .with(rerun::Scalars::descriptor_scalars(), [Scalar::from(1.0)]);
    s.row("x")
        .with(rerun::Scalars::descriptor_scalars(), [Radius::from(3.0)]);
    let e = s.flush_blocking().unwrap_err();
    assert!(e.contains("after another type"), "{e}");
}

#[test]
fn rows_become_one_chunk_per_entity_on_sim_time_and_full_chunks_go_early() {
    let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
    let mut s = RrdStream::new(rec);
    let n = CHUNK_ROWS + 10;
    for k in 0..n {
        // well within CHUNK_SPAN_S
        s.set_duration_secs("sim_time", k as f64 * 0.005);
        s.log("a", &rerun::Scalars::single(k as f64)).unwrap();
        if k % 2 == 0 {
            s.log("b", &rerun::Points3D::new([[k as f32, 0.0, 0.0]]))
                .unwrap();
        }
    }
    s.flush_blocking().unwrap();
    let got = chunks(&storage.take());
    let t = vec!["sim_time".to_string()];
    assert_eq!(
        got,
        [
            ("/a".to_string(), CHUNK_ROWS, t.clone()),
            ("/a".to_string(), 10, t.clone()),
            ("/b".to_string(), n.div_ceil(2), t),
        ]
    );
}

/// Later chunks of an entity fill the columns its earlier chunks emptied: each chunk holds
/// its own rows' values only, a component no row of a chunk has is not in it, and a
/// component may change type from one chunk to the next.
#[test]
fn later_chunks_reuse_the_emptied_columns_and_hold_only_their_rows() {
    use rerun::components::{Radius, Scalar};
    let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
    let mut s = RrdStream::new(rec);
    let scalars = rerun::Scalars::descriptor_scalars();
    let radii = rerun::Points3D::descriptor_radii();
    let chunks = 4;
    for k in 0..chunks * CHUNK_ROWS {
        let c = k / CHUNK_ROWS;
        if k % CHUNK_ROWS == 0 {
            // the chunk before last is back: this row's send hands its columns over
            s.take_emptied(true);
        }
        s.set_duration_secs("sim_time", k as f64 * 0.001);
        let row = s.row("x");
        // chunk 0: scalars and radii; chunk 1: scalars only; chunk 2: the radii
        // descriptor with scalar values; chunk 3: both again, three values a row
        match c {
            0 => row
                .with(scalars.clone(), [Scalar::from(k as f64)])
                .with(radii.clone(), [Radius::from(k as f32)]),
            1 => row.with(scalars.clone(), [Scalar::from(k as f64)]),
            2 => row.with(radii.clone(), [Scalar::from(-(k as f64))]),
            _ => row
                .with(scalars.clone(), [Scalar::from(k as f64); 3])
                .with(radii.clone(), [Radius::from(k as f32); 3]),
        };
    }
    s.flush_blocking().unwrap();
    let msgs = storage.take();
    let got = entity_chunks(&msgs, "/x");
    assert_eq!(got.len(), chunks);
    let values = |chunk: &Chunk, d: &ComponentDescriptor| {
        chunk.components().get_array(d.component).map(|a| {
            let inner = a.values();
            (a.len(), inner.len(), inner.data_type().clone())
        })
    };
    let (rows, n) = (CHUNK_ROWS, CHUNK_ROWS);
    let f64s = arrow::datatypes::DataType::Float64;
    let f32s = arrow::datatypes::DataType::Float32;
    assert_eq!(values(&got[0], &scalars), Some((rows, n, f64s.clone())));
    assert_eq!(values(&got[0], &radii), Some((rows, n, f32s.clone())));
    assert_eq!(values(&got[1], &scalars), Some((rows, n, f64s.clone())));
    assert_eq!(values(&got[1], &radii), None);
    assert_eq!(values(&got[2], &scalars), None);
    assert_eq!(values(&got[2], &radii), Some((rows, n, f64s.clone())));
    assert_eq!(values(&got[3], &scalars), Some((rows, 3 * n, f64s)));
    assert_eq!(values(&got[3], &radii), Some((rows, 3 * n, f32s)));
    // the last chunk's first scalar is its first row's, not a left-over
    let first = got[3]
        .components()
        .get_array(scalars.component)
        .unwrap()
        .value(0);
    let first = first
        .as_any()
        .downcast_ref::<arrow::array::Float64Array>()
        .unwrap();
    assert_eq!(first.value(0), (3 * CHUNK_ROWS) as f64);
}

#[test]
fn a_chunk_spans_at_most_chunk_span_s_of_sim_time() {
    let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
    let mut s = RrdStream::new(rec);
    let n = 100;
    for k in 0..n {
        s.set_duration_secs("sim_time", k as f64 * CHUNK_SPAN_S / 30.0);
        s.log("a", &rerun::Scalars::single(k as f64)).unwrap();
    }
    s.flush_blocking().unwrap();
    let rows: Vec<usize> = chunks(&storage.take()).iter().map(|c| c.1).collect();
    // a row more than the span after the chunk's first starts the next chunk
    assert_eq!(rows, [31, 31, 31, 7]);
}

#[test]
fn the_times_are_those_of_set_duration_secs() {
    let (rec, storage) = rerun::RecordingStreamBuilder::new("test").memory().unwrap();
    let mut s = RrdStream::new(rec);
    for t in [0.05, 1.0, 2.5] {
        s.set_duration_secs("sim_time", t);
        s.log("x", &rerun::Scalars::single(t)).unwrap();
    }
    s.flush_blocking().unwrap();
    let msgs = storage.take();
    let chunk = msgs
        .iter()
        .find_map(|m| match m {
            LogMsg::ArrowMsg(_, a) => Chunk::from_arrow_msg(a)
                .ok()
                .filter(|c| c.entity_path().to_string() == "/x"),
            _ => None,
        })
        .unwrap();
    let times: Vec<i64> = chunk.timelines()[&"sim_time".into()].times_raw().to_vec();
    assert_eq!(times, [50_000_000, 1_000_000_000, 2_500_000_000]);
}
