//! PNG inputs: 16-bit depth images (RGB-D frames) and 8-bit stereo images. Any bytes give an
//! image or a typed error; a depth image turns into an interval image.
#![no_main]

use fuzzyvox::io::decode_gray_image;
use fuzzyvox::io::rgbd::{decode_depth_png_mm, kinect_interval_image};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(depth) = decode_depth_png_mm(data) {
        assert_eq!(
            depth.depth.len(),
            depth.width as usize * depth.height as usize
        );
        kinect_interval_image(&depth).expect("millimetre depth gives valid intervals");
    }
    if let Ok(gray) = decode_gray_image(data) {
        assert_eq!(
            gray.pixels().len(),
            gray.width() as usize * gray.height() as usize
        );
    }
});
