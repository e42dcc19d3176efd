//! MAT v5 files written byte by byte here (little- and big-endian, plain and compressed),
//! read back; and the shipped EMPS record.

use super::*;
use std::io::Write;

/// An element: tag and data padded to 8 bytes.
fn element(order: Order, ty: u32, data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let w = |v: u32| match order {
        Order::Little => v.to_le_bytes(),
        Order::Big => v.to_be_bytes(),
    };
    out.extend_from_slice(&w(ty));
    out.extend_from_slice(&w(data.len() as u32));
    out.extend_from_slice(data);
    while out.len() % 8 != 0 {
        out.push(0);
    }
    out
}

/// A matrix element of class `class` with the real part given as raw element `real`.
fn matrix_element(order: Order, class: u32, name: &str, dims: &[i32], real: Vec<u8>) -> Vec<u8> {
    let u = |v: u32| match order {
        Order::Little => v.to_le_bytes(),
        Order::Big => v.to_be_bytes(),
    };
    let mut body = element(order, MI_UINT32, &[u(class), u(0)].concat());
    let dims_bytes: Vec<u8> = dims
        .iter()
        .flat_map(|d| match order {
            Order::Little => d.to_le_bytes(),
            Order::Big => d.to_be_bytes(),
        })
        .collect();
    body.extend(element(order, MI_INT32, &dims_bytes));
    body.extend(element(order, MI_INT8, name.as_bytes()));
    body.extend(real);
    element(order, MI_MATRIX, &body)
}

fn doubles(order: Order, v: &[f64]) -> Vec<u8> {
    let b: Vec<u8> = v
        .iter()
        .flat_map(|x| match order {
            Order::Little => x.to_le_bytes(),
            Order::Big => x.to_be_bytes(),
        })
        .collect();
    element(order, MI_DOUBLE, &b)
}

fn header(order: Order) -> Vec<u8> {
    let mut h = b"MATLAB 5.0 MAT-file, written by the hd-io tests".to_vec();
    h.resize(124, b' ');
    h.extend_from_slice(&[0x00, 0x01]);
    h.extend_from_slice(if order == Order::Little { b"IM" } else { b"MI" });
    h
}

fn compressed(element_bytes: &[u8]) -> Vec<u8> {
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(element_bytes).unwrap();
    let data = z.finish().unwrap();
    let mut out = MI_COMPRESSED.to_le_bytes().to_vec();
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend(data);
    out
}

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn reads_plain_and_compressed_vectors_in_both_byte_orders() {
    let dir = tempfile::tempdir().unwrap();
    let x = [0.0, 1.5, -2.25, 1e-300];
    for order in [Order::Little, Order::Big] {
        let mut f = header(order);
        f.extend(matrix_element(order, 6, "x", &[4, 1], doubles(order, &x)));
        // An int16 row vector stored as int16 elements.
        let ints: Vec<u8> = [3i16, -7, 11]
            .iter()
            .flat_map(|v| if order == Order::Little { v.to_le_bytes() } else { v.to_be_bytes() })
            .collect();
        f.extend(matrix_element(order, 10, "k", &[1, 3], element(order, MI_INT16, &ints)));
        let p = write(&dir, "plain.mat", &f);
        let got = read_mat_vectors(&p, &["k", "x"]).unwrap();
        assert_eq!(got, vec![vec![3.0, -7.0, 11.0], x.to_vec()]);
    }
    let mut f = header(Order::Little);
    f.extend(compressed(&matrix_element(
        Order::Little,
        6,
        "gain",
        &[1, 1],
        doubles(Order::Little, &[35.15]),
    )));
    f.extend(compressed(&matrix_element(
        Order::Little,
        6,
        "y",
        &[1, 4],
        doubles(Order::Little, &x),
    )));
    let p = write(&dir, "z.mat", &f);
    let all = read_mat(&p).unwrap();
    assert_eq!(all.len(), 2);
    assert_eq!(all[1].dims, vec![1, 4]);
    assert_eq!(read_mat_vectors(&p, &["gain", "y"]).unwrap(), vec![vec![35.15], x.to_vec()]);
}

#[test]
fn errors_name_the_file_and_variable() {
    let dir = tempfile::tempdir().unwrap();
    let o = Order::Little;
    let mut f = header(o);
    f.extend(matrix_element(o, 6, "m", &[2, 2], doubles(o, &[1.0, 2.0, 3.0, 4.0])));
    f.extend(matrix_element(o, 4, "label", &[1, 2], element(o, MI_UTF8, b"ab")));
    f.extend(matrix_element(o, 6, "bad", &[2, 1], doubles(o, &[1.0, f64::NAN])));
    let p = write(&dir, "e.mat", &f);
    let msg = |names: &[&str]| read_mat_vectors(&p, names).unwrap_err().to_string();
    let m = msg(&["m"]);
    assert!(m.contains("e.mat") && m.contains("'m' is a 2×2 matrix; expected a vector"), "{m}");
    let m = msg(&["label"]);
    assert!(m.contains("'label' is a char array"), "{m}");
    let m = msg(&["qm"]);
    assert!(m.contains("missing variable 'qm' (found: m, label, bad)"), "{m}");
    let m = msg(&["bad"]);
    assert!(m.contains("'bad', element 2"), "{m}");
    // Truncated: the last element cut in half.
    let p = write(&dir, "cut.mat", &f[..f.len() - 12]);
    let m = read_mat(&p).unwrap_err().to_string();
    assert!(m.contains("cut.mat") && m.contains("truncated"), "{m}");
    // Not a MAT file.
    let p = write(&dir, "text.mat", b"t,q\n0,1\n");
    let m = read_mat(&p).unwrap_err().to_string();
    assert!(m.contains("MAT v5"), "{m}");
    let mut v73 = b"MATLAB 7.3 MAT-file".to_vec();
    v73.resize(600, 0);
    let p = write(&dir, "h5.mat", &v73);
    assert!(read_mat(&p).unwrap_err().to_string().contains("v7.3"));
}

#[test]
fn reads_the_shipped_emps_record() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/emps/DATA_EMPS.mat");
    let v = read_mat_vectors(&path, &["t", "qm", "qg", "vir", "kp", "kv", "gtau"]).unwrap();
    let n = v[0].len();
    assert!(n > 20_000, "{n} samples");
    for col in &v[1..4] {
        assert_eq!(col.len(), n);
    }
    // Sampled at 1 kHz, strictly increasing.
    let worst = v[0].windows(2).map(|w| (w[1] - w[0] - 1e-3).abs()).fold(0.0, f64::max);
    // Measured: 2.4e-8 s (the stored times carry rounding of a float accumulation).
    assert!(worst < 3e-7, "largest deviation of a sample interval from 1 ms: {worst:e} s");
    // Scalars: the description's gains.
    assert_eq!(v[4].len(), 1);
    assert!((v[4][0] - 160.18).abs() < 0.01 && (v[5][0] - 243.45).abs() < 0.01);
    assert!((v[6][0] - 35.15).abs() < 0.01);
}
