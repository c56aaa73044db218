fn main() {
    afl::fuzz!(|data: &[u8]| orbcloud_fuzz::read_session(data));
}
