//! Round trips and every rejection of the wire format.

use crate::*;

type Scalars = Vec<(String, f64)>;

fn scalars() -> Scalars {
    vec![("mu_a".into(), 0.21), ("k_e".into(), 1.5e11)]
}

fn result_header(n: u32, fields: bool) -> ResultHeader<String, Scalars> {
    ResultHeader {
        key: "Cu/flat/015.0".into(),
        worker_index: 1,
        grid_n: n,
        solve_seconds: 0.5,
        kernels_built: 1,
        kernels_loaded: 0,
        kernels_resident: 1,
        sent_unix_ns: 42,
        field_names: if fields {
            FIELD_NAMES.iter().map(|s| s.to_string()).collect()
        } else {
            vec![]
        },
        scalars: scalars(),
    }
}

fn arrays(n: usize) -> Vec<Vec<f64>> {
    (0..FIELD_NAMES.len())
        .map(|k| {
            (0..n * n)
                .map(|i| (k * 1000 + i) as f64 * 1.000_000_1e-3 - 0.5)
                .collect()
        })
        .collect()
}

fn encode_result(h: ResultHeader<String, Scalars>, fields: &[Vec<f64>]) -> Vec<u8> {
    let refs: Vec<&[f64]> = fields.iter().map(|f| f.as_slice()).collect();
    encode_to_vec(&Envelope::new("run1", ToCoord::Result(h)), &refs).unwrap()
}

fn expect_case(id: &String) -> Option<Expected> {
    (id == "Cu/flat/015.0").then_some(Expected {
        grid_n: 4,
        want_fields: true,
    })
}

fn decode_and_validate(bytes: &[u8]) -> Result<ResultHeader<String, Scalars>, ProtocolError> {
    let d = decode_to_coord::<String, Scalars>(bytes, "run1")?;
    match d.header.body {
        ToCoord::Result(h) => {
            validate_result(&h, d.field_bytes, expect_case)?;
            Ok(h)
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn result_round_trip_is_bit_exact_and_zero_copy_when_aligned() {
    let mut fields = arrays(4);
    fields[0][0] = -0.0;
    fields[0][1] = f64::MIN_POSITIVE / 3.0; // subnormal
    fields[0][2] = f64::MAX;
    let bytes = encode_result(result_header(4, true), &fields);
    assert_eq!(&bytes[0..4], &MAGIC);
    let d = decode_to_coord::<String, Scalars>(&bytes, "run1").unwrap();
    let ToCoord::Result(h) = &d.header.body else {
        panic!("not a result")
    };
    assert_eq!(*h, result_header(4, true));
    validate_result(h, d.field_bytes, expect_case).unwrap();
    assert_eq!(d.values(), 9 * 16);
    for (k, f) in fields.iter().enumerate() {
        let got = d.field(k, 16).unwrap();
        let bits: Vec<u64> = got.iter().map(|v| v.to_bits()).collect();
        let want: Vec<u64> = f.iter().map(|v| v.to_bits()).collect();
        assert_eq!(bits, want, "field {k}");
    }
    // A Vec<u8> from the global allocator is at least 8-byte aligned here,
    // and the array region starts at a multiple of 8.
    if (bytes.as_ptr() as usize).is_multiple_of(8) {
        assert!(matches!(
            d.field(0, 16).unwrap(),
            std::borrow::Cow::Borrowed(_)
        ));
    }
    assert!(d.field(9, 16).is_none(), "past the end");
}

#[test]
fn unaligned_payload_is_copied_not_misread() {
    let fields = arrays(4);
    let bytes = encode_result(result_header(4, true), &fields);
    let mut shifted = vec![0u8; bytes.len() + 1];
    shifted[1..].copy_from_slice(&bytes);
    let d = decode_to_coord::<String, Scalars>(&shifted[1..], "run1").unwrap();
    assert_eq!(d.field(3, 16).unwrap().as_ref(), fields[3].as_slice());
}

#[test]
fn array_region_starts_on_8_byte_boundary() {
    for extra in 0..16 {
        let mut h = result_header(2, false);
        h.key = "x".repeat(extra + 1);
        let header = encode_header(&Envelope::new("r", ToCoord::Result(h))).unwrap();
        let len = frame_len(header.len(), 3);
        assert!((len - 24).is_multiple_of(8));
        assert!(len - 24 >= HEADER_OFFSET + header.len());
    }
}

#[test]
fn coordinator_messages_round_trip() {
    let case = ToWorker::Case(CaseAssignment {
        key: "Ni/circle-A/090.0".into(),
        grid_n: 64,
        want_fields: false,
        attempt: 1,
        spec: "{\"any\":\"spec\"}".to_string(),
    });
    for msg in [
        case,
        ToWorker::Done,
        ToWorker::Rejected {
            reason: "why".into(),
        },
    ] {
        let bytes = encode_to_vec(&Envelope::new("r9", msg.clone()), &[]).unwrap();
        let d = decode_to_worker::<String, String>(&bytes, "r9").unwrap();
        assert_eq!(d.header.body, msg);
        assert_eq!(d.header.version, PROTOCOL_VERSION);
    }
    let ready = ToCoord::<String, Scalars>::Ready(Ready {
        worker_index: 3,
        pid: 77,
    });
    let bytes = encode_to_vec(&Envelope::new("r9", ready.clone()), &[]).unwrap();
    assert_eq!(
        decode_to_coord::<String, Scalars>(&bytes, "r9")
            .unwrap()
            .header
            .body,
        ready
    );
}

#[test]
fn rejects_truncated_prefix_and_header() {
    let bytes = encode_result(result_header(4, true), &arrays(4));
    assert!(matches!(
        decode_to_coord::<String, Scalars>(&bytes[..5], "run1"),
        Err(ProtocolError::Truncated { .. })
    ));
    assert!(matches!(
        decode_to_coord::<String, Scalars>(&bytes[..20], "run1"),
        Err(ProtocolError::Truncated { .. })
    ));
    assert!(matches!(
        decode_to_coord::<String, Scalars>(&[], "run1"),
        Err(ProtocolError::Truncated { .. })
    ));
}

#[test]
fn rejects_bad_magic() {
    let mut bytes = encode_result(result_header(4, false), &[]);
    bytes[0] = b'X';
    assert!(matches!(
        decode_to_coord::<String, Scalars>(&bytes, "run1"),
        Err(ProtocolError::BadMagic(_))
    ));
}

#[test]
fn rejects_other_protocol_version() {
    let mut bytes = encode_result(result_header(4, false), &[]);
    bytes[4..8].copy_from_slice(&(PROTOCOL_VERSION + 1).to_le_bytes());
    assert_eq!(
        decode_to_coord::<String, Scalars>(&bytes, "run1").unwrap_err(),
        ProtocolError::Version {
            got: PROTOCOL_VERSION + 1,
            expected: PROTOCOL_VERSION
        }
    );
    // The version inside the header is checked too.
    let mut env = Envelope::new("run1", ToCoord::Result(result_header(4, false)));
    env.version = 0;
    let bytes = encode_to_vec(&env, &[]).unwrap();
    assert!(matches!(
        decode_to_coord::<String, Scalars>(&bytes, "run1"),
        Err(ProtocolError::Version { got: 0, .. })
    ));
}

#[test]
fn rejects_message_of_another_run() {
    let bytes = encode_result(result_header(4, false), &[]);
    assert!(matches!(
        decode_to_coord::<String, Scalars>(&bytes, "run2"),
        Err(ProtocolError::WrongRun { .. })
    ));
}

#[test]
fn rejects_malformed_header() {
    let mut bytes = encode_result(result_header(4, false), &[]);
    for b in bytes[HEADER_OFFSET..].iter_mut() {
        *b = 0xff;
    }
    assert!(matches!(
        decode_to_coord::<String, Scalars>(&bytes, "run1"),
        Err(ProtocolError::Header(_))
    ));
    // A worker message is not a coordinator message.
    let bytes = encode_result(result_header(4, false), &[]);
    assert!(decode_to_worker::<String, String>(&bytes, "run1").is_err());
}

#[test]
fn rejects_trailing_bytes_after_coordinator_message() {
    let bytes = encode_to_vec(
        &Envelope::new("r", ToWorker::<String, String>::Done),
        &[&[1.0]],
    )
    .unwrap();
    assert!(matches!(
        decode_to_worker::<String, String>(&bytes, "r"),
        Err(ProtocolError::Header(_))
    ));
}

#[test]
fn rejects_case_without_grid() {
    let case = ToWorker::Case(CaseAssignment {
        key: "a".to_string(),
        grid_n: 0,
        want_fields: false,
        attempt: 0,
        spec: String::new(),
    });
    let bytes = encode_to_vec(&Envelope::new("r", case), &[]).unwrap();
    assert!(matches!(
        decode_to_worker::<String, String>(&bytes, "r"),
        Err(ProtocolError::Invalid { .. })
    ));
}

#[test]
fn rejects_result_for_unknown_case() {
    let mut h = result_header(4, true);
    h.key = "Zz/flat/000.0".into();
    let bytes = encode_result(h, &arrays(4));
    assert_eq!(
        decode_and_validate(&bytes).unwrap_err(),
        ProtocolError::UnknownCase("Zz/flat/000.0".into())
    );
}

#[test]
fn rejects_grid_mismatch() {
    let bytes = encode_result(result_header(5, true), &arrays(5));
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::Grid {
            got: 5,
            expected: 4,
            ..
        })
    ));
}

#[test]
fn rejects_wrong_array_lengths() {
    let mut short = arrays(4);
    short[8].pop();
    let bytes = encode_result(result_header(4, true), &short);
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::FieldLength { .. })
    ));
    let mut long = arrays(4);
    long[2].push(1.0);
    let bytes = encode_result(result_header(4, true), &long);
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::FieldLength { .. })
    ));
    // Raw bytes that are not a whole number of f64.
    let mut bytes = encode_result(result_header(4, true), &arrays(4));
    bytes.push(0);
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::FieldLength { .. })
    ));
}

#[test]
fn rejects_missing_or_unrequested_fields() {
    let bytes = encode_result(result_header(4, false), &[]);
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::FieldCount {
            got: 0,
            expected: 9,
            ..
        })
    ));
}

#[test]
fn rejects_unknown_or_repeated_field_name() {
    let mut h = result_header(4, true);
    h.field_names[3] = "temperature".into();
    let bytes = encode_result(h, &arrays(4));
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::FieldName { .. })
    ));
    let mut h = result_header(4, true);
    h.field_names[3] = "p".into();
    let bytes = encode_result(h, &arrays(4));
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::FieldName { .. })
    ));
}

#[test]
fn rejects_non_finite_scalars() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut h = result_header(4, true);
        h.scalars[1].1 = bad;
        let bytes = encode_result(h, &arrays(4));
        assert_eq!(
            decode_and_validate(&bytes).unwrap_err(),
            ProtocolError::NonFinite {
                case_id: "Cu/flat/015.0".into(),
                name: "k_e".into()
            }
        );
    }
}

#[test]
fn rejects_impossible_timing() {
    let mut h = result_header(4, true);
    h.solve_seconds = -1.0;
    let bytes = encode_result(h, &arrays(4));
    assert!(matches!(
        decode_and_validate(&bytes),
        Err(ProtocolError::Invalid { .. })
    ));
}

#[test]
fn corrupted_payloads_never_panic() {
    let base = encode_result(result_header(4, true), &arrays(4));
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    for _ in 0..2000 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let mut bytes = base.clone();
        let at = (state >> 33) as usize % bytes.len();
        bytes[at] ^= (state >> 17) as u8 | 1;
        let cut = (state >> 7) as usize % (bytes.len() + 1);
        let _ = decode_and_validate(&bytes[..cut.max(at + 1).min(bytes.len())]);
        let _ = decode_to_worker::<String, String>(&bytes, "run1");
    }
}

#[test]
fn encode_into_checks_buffer_size() {
    let header = encode_header(&Envelope::new("r", ToWorker::<String, String>::Done)).unwrap();
    let mut buf = vec![0u8; frame_len(header.len(), 0) + 8];
    assert!(matches!(
        encode_into(&mut buf, &header, &[]),
        Err(ProtocolError::BufferSize { .. })
    ));
}

#[test]
fn names_are_scoped_by_run() {
    assert_eq!(work_service("r1"), "r1/work");
    assert_eq!(to_coord_event("r1"), "r1/to-coord");
    assert_eq!(to_workers_event("r1"), "r1/to-workers");
    assert_eq!(coord_node_name("r1"), "r1-coord");
    assert_eq!(worker_node_name("r1", 3), "r1-worker-3");
    assert_ne!(work_service("r1"), work_service("r2"));
}

#[test]
fn ipc_config_uses_fixed_prefix_and_private_root() {
    let cfg = ipc_config().unwrap();
    let prefix = cfg.global.prefix.to_string();
    assert!(prefix.starts_with(IPC_PREFIX), "{prefix}");
    let root = ipc_root_dir().unwrap();
    use std::os::unix::fs::MetadataExt;
    let meta = std::fs::metadata(&root).unwrap();
    assert_eq!(
        meta.mode() & 0o077,
        0,
        "root {} open to others",
        root.display()
    );
    assert!(cfg
        .global
        .root_path()
        .to_string()
        .starts_with(root.to_str().unwrap()));
}
