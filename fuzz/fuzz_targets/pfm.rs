//! PFM float maps: any bytes give an image or a typed error; a decoded image re-encodes to the
//! same samples, bit for bit.
#![no_main]

use fuzzyvox::io::pfm::{encode_pfm, parse_pfm};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(image) = parse_pfm(data) {
        assert_eq!(
            image.data.len(),
            image.width as usize * image.height as usize
        );
        let bytes = encode_pfm(image.width, image.height, &image.data).expect("valid image");
        let again = parse_pfm(&bytes).expect("an encoded image decodes");
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&again.data), bits(&image.data));
    }
});
