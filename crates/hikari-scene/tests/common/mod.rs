//! What the glTF tests share: they build their files in code, buffers as base64 data URIs.

/// Standard base64 with padding (RFC 4648), for `data:` URIs.
#[allow(dead_code)]
pub fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for i in 0..4 {
            if i <= c.len() {
                out.push(T[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Writes `doc` as `<test>/<name>/<name>.gltf` under the tests' scratch folder; returns its path.
#[allow(dead_code)]
pub fn write_gltf_doc(test: &str, name: &str, doc: &serde_json::Value) -> std::path::PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(test)
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_vec_pretty(doc).unwrap()).unwrap();
    path
}
