//! Several scans at once: how a map that integrates a list of scans groups them.
//!
//! A scan's rays are walked in parallel pieces, but a small scan (a depth image's few thousand
//! points) leaves the threads little to share and pays each parallel step's set-up. A map given
//! many scans therefore walks the scans of a group side by side, each into its own record, and
//! then applies the records one after another in the scans' order, so the map is bit for bit
//! what integrating the scans one at a time gives. Groups bound the records held at once.

use super::cloud::PointCloud;

/// Scans per group, per thread.
const SCANS_PER_THREAD: usize = 2;

/// Consecutive groups of `clouds`, in order, covering all of them: each holds at most
/// [`SCANS_PER_THREAD`] scans per thread and, unless it is a single scan, at most `max_points`
/// points.
pub(crate) fn scan_groups(clouds: &[PointCloud], max_points: usize) -> Vec<&[PointCloud]> {
    let most = (rayon::current_num_threads() * SCANS_PER_THREAD).max(1);
    let mut groups = Vec::new();
    let mut rest = clouds;
    while !rest.is_empty() {
        let mut len = 1;
        let mut points = rest[0].len();
        while len < rest.len() && len < most && points + rest[len].len() <= max_points {
            points += rest[len].len();
            len += 1;
        }
        let (group, tail) = rest.split_at(len);
        groups.push(group);
        rest = tail;
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    fn cloud(points: usize) -> PointCloud {
        PointCloud::new(Point3::origin(), vec![Point3::new(1.0, 0.0, 0.0); points]).unwrap()
    }

    #[test]
    fn groups_keep_order_and_bounds() {
        let clouds: Vec<PointCloud> = [5, 5, 5, 20, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5]
            .iter()
            .map(|&n| cloud(n))
            .collect();
        let groups = scan_groups(&clouds, 12);
        let flat: Vec<usize> = groups
            .iter()
            .flat_map(|g| g.iter().map(PointCloud::len))
            .collect();
        let sizes: Vec<usize> = clouds.iter().map(PointCloud::len).collect();
        assert_eq!(flat, sizes);
        let most = rayon::current_num_threads() * SCANS_PER_THREAD;
        for group in &groups {
            assert!(!group.is_empty() && group.len() <= most);
            let points: usize = group.iter().map(PointCloud::len).sum();
            assert!(
                group.len() == 1 || points <= 12,
                "{points} points in {}",
                group.len()
            );
        }
        // A scan larger than the bound is a group of its own.
        assert!(groups.iter().any(|g| g.len() == 1 && g[0].len() == 20));
        assert!(scan_groups(&[], 12).is_empty());
    }
}
