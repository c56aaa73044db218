fn main() {
    afl::fuzz!(|data: &[u8]| orbcloud_fuzz::read_as("fuzz.json", data));
}
