// The thin singular value decomposition the separability metric starts from (metrics.cpp).
#pragma once

#include <Eigen/Core>

namespace halfback::study::detail {

struct ThinSvd {
  Eigen::MatrixXd u;       // rows × k, k = min(rows, cols)
  Eigen::VectorXd values;  // k singular values, descending
  Eigen::MatrixXd v;       // cols × k
};

// Eigen's BDCSVD. In a translation unit of its own, compiled at -O1 in release builds: its
// template instantiation was 30 s of the build's 2 minutes, and at -O1 the decomposition of a
// 512 × 512 matrix (the study's 4D tables) takes 1.2x as long, for a metric that computes it once
// per table (docs/performance.md, "Building"). The numbers do not depend on the level.
ThinSvd thin_svd(const Eigen::MatrixXd& m);

}  // namespace halfback::study::detail
