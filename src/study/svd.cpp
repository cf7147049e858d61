#include "svd.hpp"

#include <Eigen/SVD>

namespace halfback::study::detail {

ThinSvd thin_svd(const Eigen::MatrixXd& m) {
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(m, Eigen::ComputeThinU | Eigen::ComputeThinV);
  return {svd.matrixU(), svd.singularValues(), svd.matrixV()};
}

}  // namespace halfback::study::detail
