//! FNV-1a, 64 bits: a stable, non-cryptographic hash (the same on every machine and
//! build) for the fingerprints, checksums and configuration hashes of the files tapsim
//! writes and reads back. It detects accidental and casual changes, not forgeries.

/// FNV-1a's offset basis: the hash of nothing.
pub const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a of `bytes` continued from the hash `h` of what came before them.
pub const fn continued(mut h: u64, bytes: &[u8]) -> u64 {
    let mut i = 0;
    while i < bytes.len() {
        h ^= bytes[i] as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
        i += 1;
    }
    h
}

/// FNV-1a of `bytes`.
pub const fn hash(bytes: &[u8]) -> u64 {
    continued(OFFSET, bytes)
}
