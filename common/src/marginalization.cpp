#include "livo/marginalization.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "livo/quaternion_manifold.hpp"
#include "livo/so3.hpp"

namespace livo {

MarginalPriorFactor::MarginalPriorFactor(std::shared_ptr<const MarginalPrior> prior) : prior_(std::move(prior)) {
  set_num_residuals(static_cast<int>(prior_->J.rows()));
  for (int s : prior_->sizes) mutable_parameter_block_sizes()->push_back(s);
}

bool MarginalPriorFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const MarginalPrior& m = *prior_;
  const int rows = static_cast<int>(m.J.rows());
  Eigen::VectorXd dx(m.tangentSize());
  int offset = 0;
  for (size_t b = 0; b < m.blocks.size(); ++b) {
    const double* x = parameters[b];
    if (m.quaternion[b]) {
      const Eigen::Map<const Eigen::Quaterniond> q(x), q0(m.x0[b].data());
      dx.segment<3>(offset) = so3::Log(Quat(q0.inverse() * q));
      offset += 3;
    } else {
      const int n = m.sizes[b];
      dx.segment(offset, n) = Eigen::Map<const Eigen::VectorXd>(x, n) - m.x0[b];
      offset += n;
    }
  }
  Eigen::Map<Eigen::VectorXd>(residuals, rows) = m.r0 + m.J * dx;
  if (!jacobians) return true;
  offset = 0;
  for (size_t b = 0; b < m.blocks.size(); ++b) {
    const int local = m.quaternion[b] ? 3 : m.sizes[b];
    if (jacobians[b]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Jb(jacobians[b], rows,
                                                                                            m.sizes[b]);
      if (m.quaternion[b]) {
        Eigen::Matrix<double, 3, 4, Eigen::RowMajor> D;
        minusAmbientJacobian(m.x0[b].data(), parameters[b], D.data());
        Jb = m.J.middleCols(offset, 3) * D;
      } else {
        Jb = m.J.middleCols(offset, local);
      }
    }
    offset += local;
  }
  return true;
}

MarginalPrior movedPrior(const MarginalPrior& prior, const std::vector<WorldMotion>& motion, const Pose3& T) {
  if (motion.size() != prior.blocks.size())
    throw std::invalid_argument("movedPrior: " + std::to_string(motion.size()) + " motions for " +
                                std::to_string(prior.blocks.size()) + " blocks");
  const Mat3 R = T.linear();
  const Eigen::Quaterniond qR(R);
  MarginalPrior moved = prior;
  int offset = 0;
  for (size_t b = 0; b < prior.blocks.size(); ++b) {
    const int local = prior.quaternion[b] ? 3 : prior.sizes[b];
    const bool three = !prior.quaternion[b] && prior.sizes[b] == 3;
    switch (motion[b]) {
      case WorldMotion::kNone: break;
      case WorldMotion::kRotation: {
        if (!prior.quaternion[b]) throw std::invalid_argument("movedPrior: a rotation on a Euclidean block");
        const Eigen::Map<const Eigen::Quaterniond> q0(prior.x0[b].data());
        Eigen::Map<Eigen::Quaterniond> q0_moved(moved.x0[b].data());
        q0_moved = (qR * q0).normalized();
        break;
      }
      case WorldMotion::kPoint:
      case WorldMotion::kDirection: {
        if (!three) throw std::invalid_argument("movedPrior: a point or direction on a block not of size 3");
        const Vec3 x0 = prior.x0[b];
        moved.x0[b] = motion[b] == WorldMotion::kPoint ? Vec3(R * x0 + T.translation()) : Vec3(R * x0);
        moved.J.middleCols(offset, 3) = prior.J.middleCols(offset, 3) * R.transpose();
        break;
      }
    }
    offset += local;
  }
  return moved;
}

void Marginalizer::addFactor(const ceres::CostFunction* cost, std::vector<double*> blocks,
                             const ceres::LossFunction* loss) {
  factors_.push_back({cost, std::move(blocks), loss});
}

void Marginalizer::linearize(const std::vector<double*>& order, std::map<const double*, int>* ambient,
                             Eigen::MatrixXd* H_out, Eigen::VectorXd* g_out) const {
  std::map<const double*, int> offset;
  int total = 0;
  for (double* b : order) {
    offset[b] = total;
    total += quaternions_.count(b) ? 3 : (*ambient)[b];
  }
  Eigen::MatrixXd& H = *H_out;
  Eigen::VectorXd& g = *g_out;
  H = Eigen::MatrixXd::Zero(total, total);
  g = Eigen::VectorXd::Zero(total);
  const RightQuaternionManifold manifold;
  for (const Factor& f : factors_) {
    const int rows = f.cost->num_residuals();
    const size_t nb = f.blocks.size();
    Eigen::VectorXd r(rows);
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Jamb(nb);
    std::vector<double*> jac(nb);
    for (size_t k = 0; k < nb; ++k) {
      Jamb[k].resize(rows, f.cost->parameter_block_sizes()[k]);
      jac[k] = Jamb[k].data();
    }
    if (!f.cost->Evaluate(f.blocks.data(), r.data(), jac.data())) continue;
    double weight = 1.0;
    if (f.loss) {
      double rho[3];
      f.loss->Evaluate(r.squaredNorm(), rho);
      weight = std::sqrt(std::max(rho[1], 0.0));
      r *= weight;
    }
    std::vector<Eigen::MatrixXd> Jloc(nb);
    for (size_t k = 0; k < nb; ++k) {
      if (quaternions_.count(f.blocks[k])) {
        Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
        manifold.PlusJacobian(f.blocks[k], P.data());
        Jloc[k] = weight * Jamb[k] * P;
      } else {
        Jloc[k] = weight * Jamb[k];
      }
    }
    for (size_t a = 0; a < nb; ++a) {
      const int oa = offset[f.blocks[a]];
      g.segment(oa, Jloc[a].cols()) += Jloc[a].transpose() * r;
      for (size_t b = 0; b < nb; ++b)
        H.block(oa, offset[f.blocks[b]], Jloc[a].cols(), Jloc[b].cols()) += Jloc[a].transpose() * Jloc[b];
    }
  }
}

std::vector<double*> Marginalizer::blockOrder(const std::set<const double*>& first,
                                              std::map<const double*, int>* ambient) const {
  // every block the factors touch: those of `first`, then the others, in first-seen order
  std::vector<double*> order;
  for (int pass = 0; pass < 2; ++pass)
    for (const Factor& f : factors_)
      for (size_t k = 0; k < f.blocks.size(); ++k) {
        double* b = f.blocks[k];
        if ((first.count(b) > 0) != (pass == 0) || ambient->count(b)) continue;
        (*ambient)[b] = f.cost->parameter_block_sizes()[k];
        order.push_back(b);
      }
  return order;
}

bool Marginalizer::marginalInformation(const std::vector<const double*>& keep, Eigen::MatrixXd* info) const {
  std::set<const double*> drop;
  for (const Factor& f : factors_)
    for (double* b : f.blocks)
      if (std::find(keep.begin(), keep.end(), b) == keep.end()) drop.insert(b);
  std::map<const double*, int> ambient;
  std::vector<double*> order = blockOrder(drop, &ambient);
  // the kept blocks last, in the order asked for
  order.resize(
      static_cast<size_t>(std::count_if(order.begin(), order.end(), [&](double* b) { return drop.count(b) > 0; })));
  int k = 0;
  for (const double* b : keep) {
    if (!ambient.count(b)) return false;  // touched by no factor: no information
    order.push_back(const_cast<double*>(b));
    k += quaternions_.count(b) ? 3 : ambient[b];
  }
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  linearize(order, &ambient, &H, &g);
  const Eigen::Index m = H.rows() - k;
  if (m == 0) {
    *info = H;
    return true;
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(H.topLeftCorner(m, m));  // reads the lower triangle
  if (llt.info() != Eigen::Success) return false;
  const Eigen::MatrixXd Hmr = H.topRightCorner(m, k);
  const Eigen::MatrixXd L_inv_Hmr = llt.matrixL().solve(Hmr);
  Eigen::MatrixXd Hp = H.bottomRightCorner(k, k) - L_inv_Hmr.transpose() * L_inv_Hmr;
  *info = 0.5 * (Hp + Hp.transpose());
  return info->allFinite();
}

std::shared_ptr<MarginalPrior> Marginalizer::marginalize(const std::set<const double*>& drop, double eps) const {
  // every block the factors touch: the dropped ones first, then the kept ones, in first-seen order
  std::map<const double*, int> ambient;
  const std::vector<double*> order = blockOrder(drop, &ambient);
  int total = 0, dropped = 0;
  for (double* b : order) {
    const int local = quaternions_.count(b) ? 3 : ambient[b];
    total += local;
    if (drop.count(b)) dropped += local;
  }
  if (total == dropped) return nullptr;

  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  linearize(order, &ambient, &H, &g);

  // Schur complement of the dropped block
  const int m = dropped, k = total - dropped;
  const Eigen::MatrixXd Hmm = 0.5 * (H.topLeftCorner(m, m) + H.topLeftCorner(m, m).transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> em(Hmm);
  const double mmax = em.eigenvalues().size() ? std::max(em.eigenvalues().maxCoeff(), 0.0) : 0.0;
  const Eigen::VectorXd inv =
      (em.eigenvalues().array() > eps * mmax).select(em.eigenvalues().array().inverse(), 0.0).matrix();
  const Eigen::MatrixXd Hmm_inv = em.eigenvectors() * inv.asDiagonal() * em.eigenvectors().transpose();
  const Eigen::MatrixXd Hrm = H.bottomLeftCorner(k, m);
  Eigen::MatrixXd Hp = H.bottomRightCorner(k, k) - Hrm * Hmm_inv * Hrm.transpose();
  const Eigen::VectorXd gp = g.tail(k) - Hrm * Hmm_inv * g.head(m);
  Hp = (0.5 * (Hp + Hp.transpose())).eval();  // .eval(): the right side reads what the left writes

  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ep(Hp);
  const double pmax = std::max(ep.eigenvalues().maxCoeff(), 0.0);
  std::vector<int> keep;
  for (int i = 0; i < k; ++i)
    if (ep.eigenvalues()(i) > eps * pmax && ep.eigenvalues()(i) > 0.0) keep.push_back(i);
  auto prior = std::make_shared<MarginalPrior>();
  prior->J.resize(static_cast<int>(keep.size()), k);
  prior->r0.resize(static_cast<int>(keep.size()));
  for (size_t i = 0; i < keep.size(); ++i) {
    const double s = std::sqrt(ep.eigenvalues()(keep[i]));
    const Eigen::VectorXd v = ep.eigenvectors().col(keep[i]);
    prior->J.row(static_cast<int>(i)) = s * v.transpose();
    prior->r0(static_cast<int>(i)) = v.dot(gp) / s;
  }
  for (double* b : order) {
    if (drop.count(b)) continue;
    prior->blocks.push_back(b);
    prior->sizes.push_back(ambient[b]);
    prior->quaternion.push_back(quaternions_.count(b) > 0);
    prior->x0.push_back(Eigen::Map<const Eigen::VectorXd>(b, ambient[b]));
  }
  return prior;
}

}  // namespace livo
