use nalgebra::{Isometry3, Matrix3, Matrix4, Rotation3, Translation3, UnitQuaternion};

use crate::error::{Error, Result};

/// How far `RᵀR` may stray from the identity (and `det R` from 1) for a matrix to count as a
/// rotation. Poses read from text files carry a few digits only, so this is loose on purpose.
const ORTHONORMAL_TOLERANCE: f64 = 1e-3;

/// Checks that a pose is usable: finite translation and a finite unit quaternion.
pub fn validate_pose(world_from_camera: &Isometry3<f64>) -> Result<()> {
    let t = &world_from_camera.translation.vector;
    let q = world_from_camera.rotation.coords;
    if t.iter().chain(q.iter()).any(|v| !v.is_finite()) {
        return Err(Error::InvalidPose(
            "non-finite translation or rotation".into(),
        ));
    }
    if (q.norm() - 1.0).abs() > 1e-6 {
        return Err(Error::InvalidPose(format!(
            "rotation quaternion has norm {}, not 1",
            q.norm()
        )));
    }
    Ok(())
}

/// Builds a pose from a 4×4 homogeneous matrix (for example one row-major `frame-N.pose.txt`).
///
/// The matrix must be finite, its last row `0 0 0 1`, and its upper-left 3×3 block a proper
/// rotation (orthonormal to within 1e-3, determinant +1). The rotation is the unit quaternion of
/// the block as written, by Shepperd's method, as ROS tools turn a matrix into a transform's
/// quaternion: a folder of pose files and a robot recording written from it give the same
/// poses, bit for bit. (The few digits of a text pose make the block slightly non-orthonormal;
/// the quaternion is within that rounding of the nearest rotation.)
pub fn pose_from_matrix(matrix: &Matrix4<f64>) -> Result<Isometry3<f64>> {
    if matrix.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidPose("matrix has non-finite entries".into()));
    }
    let last_row = matrix.fixed_view::<1, 4>(3, 0);
    if (last_row[0].abs() + last_row[1].abs() + last_row[2].abs() + (last_row[3] - 1.0).abs())
        > 1e-9
    {
        return Err(Error::InvalidPose(format!(
            "last row must be 0 0 0 1, got {} {} {} {}",
            last_row[0], last_row[1], last_row[2], last_row[3]
        )));
    }
    let r: Matrix3<f64> = matrix.fixed_view::<3, 3>(0, 0).into_owned();
    let deviation = (r.transpose() * r - Matrix3::identity()).abs().max();
    if deviation > ORTHONORMAL_TOLERANCE {
        return Err(Error::InvalidPose(format!(
            "rotation block is not orthonormal (max |RᵀR - I| = {deviation:.3e})"
        )));
    }
    let det = r.determinant();
    if (det - 1.0).abs() > ORTHONORMAL_TOLERANCE {
        return Err(Error::InvalidPose(format!(
            "rotation block has determinant {det:.4}, not +1 (a reflection?)"
        )));
    }
    let rotation = quaternion_of(&r);
    let t = matrix.fixed_view::<3, 1>(0, 3);
    Ok(Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        rotation,
    ))
}

/// The unit quaternion of a near-rotation matrix: Shepperd's method on the matrix as given
/// (nalgebra's `from_rotation_matrix` is that method), then divided by its length summed in the
/// order x, y, z, w, as NumPy and most ROS tools do.
fn quaternion_of(r: &Matrix3<f64>) -> UnitQuaternion<f64> {
    let q =
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r)).into_inner();
    let length = (q.i * q.i + q.j * q.j + q.k * q.k + q.w * q.w).sqrt();
    UnitQuaternion::from_quaternion(q / length)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn matrix_round_trip() {
        let pose = Isometry3::new(Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.3, -0.2, 1.1));
        let back = pose_from_matrix(&pose.to_homogeneous()).unwrap();
        assert!((back.to_homogeneous() - pose.to_homogeneous()).abs().max() < 1e-9);
        validate_pose(&back).unwrap();
    }

    #[test]
    fn rejects_non_rotations() {
        let mut m = Matrix4::identity();
        m[(0, 0)] = 2.0;
        assert!(pose_from_matrix(&m).is_err());
        let mut reflection = Matrix4::identity();
        reflection[(2, 2)] = -1.0;
        assert!(pose_from_matrix(&reflection).is_err());
        let mut nan = Matrix4::identity();
        nan[(0, 3)] = f64::NAN;
        assert!(pose_from_matrix(&nan).is_err());
        let mut projective = Matrix4::identity();
        projective[(3, 0)] = 0.1;
        assert!(pose_from_matrix(&projective).is_err());
    }

    #[test]
    fn rejects_non_finite_isometry() {
        let mut pose = Isometry3::identity();
        pose.translation.vector.x = f64::INFINITY;
        assert!(validate_pose(&pose).is_err());
    }
}
