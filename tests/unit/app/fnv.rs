//! Tests of `tapsim::app::fnv` (src/app/fnv.rs).

#[test]
fn the_published_test_vectors() {
    assert_eq!(tapsim::app::fnv::hash(b""), 0xcbf2_9ce4_8422_2325);
    assert_eq!(tapsim::app::fnv::hash(b"a"), 0xaf63_dc4c_8601_ec8c);
    assert_eq!(tapsim::app::fnv::hash(b"foobar"), 0x8594_4171_f739_67e8);
}
