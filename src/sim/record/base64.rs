//! Standard base64 (RFC 4648, padded), encoded into a caller's buffer: the bytes of every
//! recorded frame pass through here, so it uses the SIMD encoder of `base64-simd` (several
//! times faster than a scalar one on the 250 kB of a raw frame) and allocates nothing.

/// Length of the encoding of `n` bytes, padding included.
pub fn encoded_len(n: usize) -> usize {
    n.div_ceil(3) * 4
}

/// Encodes `src` into `dst`, which must be at least [`encoded_len`]`(src.len())` long
/// (the rest is left as it was); returns the length written, 0 when `dst` is too short.
pub fn encode_into(src: &[u8], dst: &mut [u8]) -> usize {
    let n = encoded_len(src.len());
    match dst.get_mut(..n) {
        Some(out) => base64_simd::STANDARD
            .encode(src, base64_simd::Out::from_slice(out))
            .len(),
        None => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(src: &[u8]) -> String {
        let mut out = vec![0u8; encoded_len(src.len())];
        encode_into(src, &mut out);
        String::from_utf8(out).unwrap()
    }

    /// RFC 4648's test vectors.
    #[test]
    fn rfc_4648_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(encode(plain.as_bytes()), coded);
        }
        let all: Vec<u8> = (0..=255u8).collect();
        assert_eq!(
            encode(&all),
            "AAECAwQFBgcICQoLDA0ODxAREhMUFRYXGBkaGxwdHh8gISIjJCUmJygpKissLS4vMDEyMzQ1Njc4OTo7PD0+P0BBQkNERUZHSElKS0xNTk9QUVJTVFVWV1hZWltcXV5fYGFiY2RlZmdoaWprbG1ub3BxcnN0dXZ3eHl6e3x9fn+AgYKDhIWGh4iJiouMjY6PkJGSk5SVlpeYmZqbnJ2en6ChoqOkpaanqKmqq6ytrq+wsbKztLW2t7i5uru8vb6/wMHCw8TFxsfIycrLzM3Oz9DR0tPU1dbX2Nna29zd3t/g4eLj5OXm5+jp6uvs7e7v8PHy8/T19vf4+fr7/P3+/w=="
        );
    }
}
