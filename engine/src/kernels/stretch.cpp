#include <Eigen/Eigenvalues>

#include "gpa/engine/kernels.hpp"

namespace gpa {

double largest_isochoric_stretch(const std::array<double, 6>& b) {
    const Mat<3> m = symmetric_matrix(b);
    // The closed-form eigenvalues of a symmetric 3x3 matrix (ascending): no iteration, a few dozen
    // operations per node.
    Eigen::SelfAdjointEigenSolver<Mat<3>> eigen;
    eigen.computeDirect(m, Eigen::EigenvaluesOnly);
    const double determinant = m.determinant();
    if (!(determinant > 0.0)) return 1.0;  // no deformation gives this B (a store whose B was never set)
    return std::max(1.0, std::sqrt(eigen.eigenvalues()(2) / std::cbrt(determinant)));
}

}  // namespace gpa
