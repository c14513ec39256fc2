// Pinocchio timing baseline for armsim.
//
// Our own harness (no Pinocchio code is copied here); it only calls the public
// Pinocchio API of the `pin` / `libpinocchio` PyPI wheel. See README.md.
//
// Usage: bench [options] robot.urdf [more.urdf ...]
//   --mimic          parse URDF <mimic> tags as Pinocchio mimic joints
//                    (default: off = Pinocchio's default, mimic joints become
//                    independent DOFs)
//   --reps R         timing repetitions per algorithm (default 51; median reported)
//   --rep-ms T       target wall time of one repetition in ms (default 2)
//   --states S       number of random states (default 256)
//   --seed X         RNG seed (default 42)
//   --algos a,b,...  subset of fk,jacobians,rnea,crba,crba_upper,aba,rnea_derivatives,
//                    aba_derivatives,minverse
//
// Prints one JSON object per (model, algo) on stdout; diagnostics on stderr.
//
// Two build variants share this file (see build.sh):
//   hdr (default): every Pinocchio algorithm template is instantiated in THIS
//                  translation unit, i.e. compiled by our g++ -O3 baseline
//                  x86-64 flags.
//   lib (-DBENCH_LIB): PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION is defined and
//                  all state vectors are passed as Eigen::Ref<const VectorXd>,
//                  so the calls hit the pre-compiled explicit instantiations
//                  inside the wheel's libpinocchio_default.so (built by the
//                  wheel maintainers with GCC 14, baseline x86-64, no AVX).

#ifdef BENCH_LIB
  #ifndef PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION
    #define PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION
  #endif
  #define BENCH_VARIANT "lib"
#else
  #ifdef PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION
    #error "hdr variant must not define PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION"
  #endif
  #define BENCH_VARIANT "hdr"
#endif

#include <pinocchio/multibody.hpp> // Model, Data (Pinocchio 4 layout)
#include <pinocchio/parsers/urdf.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace
{
  using VectorXd = Eigen::VectorXd;
  using Clock = std::chrono::steady_clock;

#ifdef BENCH_LIB
  typedef Eigen::Ref<const VectorXd> Arg;
#else
  typedef const VectorXd & Arg;
#endif

  struct Options
  {
    bool mimic = false;
    int reps = 51;
    double rep_ms = 2.0;
    int states = 256;
    unsigned long long seed = 42;
    std::vector<std::string> algos = {"fk",  "jacobians",        "rnea",            "crba",
                                      "crba_upper", "aba", "rnea_derivatives", "aba_derivatives",
                                      "minverse"};
    std::vector<std::string> urdfs;
  };

  std::string stem(const std::string & path)
  {
    std::string base = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
    const std::size_t dot = base.rfind('.');
    return dot == std::string::npos ? base : base.substr(0, dot);
  }

  // One random configuration, per joint:
  //  * nq == 1 (revolute / prismatic / helical ...): uniform in
  //    [lowerPositionLimit, upperPositionLimit]; if that range is not finite
  //    (or absurdly large) use [-pi, pi].
  //  * nq == 2, nv == 1 (RevoluteUnbounded = URDF "continuous"):
  //    theta ~ U[-pi, pi], q = (cos theta, sin theta).
  //  * nq == 0 (mimic joint with --mimic): nothing to sample.
  //  * anything else: pinocchio::neutral values (warned once).
  VectorXd randomConfig(const pinocchio::Model & model, std::mt19937_64 & rng, bool & warned)
  {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    VectorXd q = pinocchio::neutral(model);
    for (pinocchio::JointIndex j = 1; j < (pinocchio::JointIndex)model.njoints; ++j)
    {
      const auto & jm = model.joints[j];
      const int nq = jm.nq(), nv = jm.nv(), iq = jm.idx_q();
      if (nq == 0)
        continue;
      if (nq == 1)
      {
        double lo = model.lowerPositionLimit[iq], hi = model.upperPositionLimit[iq];
        if (!std::isfinite(lo) || !std::isfinite(hi) || hi < lo || hi - lo > 1e6)
        {
          lo = -M_PI;
          hi = M_PI;
        }
        q[iq] = lo + (hi - lo) * u01(rng);
      }
      else if (nq == 2 && nv == 1)
      {
        const double th = -M_PI + 2.0 * M_PI * u01(rng);
        q[iq] = std::cos(th);
        q[iq + 1] = std::sin(th);
      }
      else if (!warned)
      {
        std::fprintf(
          stderr, "warning: joint %s (%s) left at neutral configuration\n", model.names[j].c_str(),
          jm.shortname().c_str());
        warned = true;
      }
    }
    return q;
  }

  VectorXd randomVec(int n, std::mt19937_64 & rng)
  {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    VectorXd x(n);
    for (int i = 0; i < n; ++i)
      x[i] = u(rng);
    return x;
  }

  struct Timing
  {
    double median, min, max;
    long calls_per_rep;
  };

  // `call(k)` runs the algorithm on state k and returns one output scalar
  // (accumulated into a sink so nothing can be optimised away).
  // The state index cycles 0..nstates-1 continuously across warm-up and all
  // repetitions; one repetition is `n` consecutive calls lasting ~opt.rep_ms.
  template<typename F>
  Timing timeIt(F && call, int nstates, const Options & opt, double & sink)
  {
    double acc = 0.0;
    int k = 0;
    // Warm-up: at least 4 full cycles over the states and at least 50 ms.
    long calls = 0;
    const auto w0 = Clock::now();
    do
    {
      for (int i = 0; i < nstates; ++i)
        acc += call(i);
      calls += nstates;
    } while (std::chrono::duration<double, std::milli>(Clock::now() - w0).count() < 50.0
             || calls < 4L * nstates);
    const double warm_ns = std::chrono::duration<double, std::nano>(Clock::now() - w0).count();
    const double est_ns = warm_ns / (double)calls;
    long n = (long)std::ceil(opt.rep_ms * 1e6 / est_ns);
    if (n < 1)
      n = 1;

    std::vector<double> per_call(opt.reps);
    for (int r = 0; r < opt.reps; ++r)
    {
      const auto t0 = Clock::now();
      for (long c = 0; c < n; ++c)
      {
        acc += call(k);
        if (++k == nstates)
          k = 0;
      }
      const auto t1 = Clock::now();
      per_call[r] = std::chrono::duration<double, std::nano>(t1 - t0).count() / (double)n;
    }
    sink += acc;
    std::vector<double> s = per_call;
    std::sort(s.begin(), s.end());
    return Timing{s[s.size() / 2], s.front(), s.back(), n};
  }

  bool wanted(const Options & opt, const std::string & a)
  {
    return std::find(opt.algos.begin(), opt.algos.end(), a) != opt.algos.end();
  }

  std::string jsonEscape(const std::string & s)
  {
    std::string o;
    for (char c : s)
    {
      if (c == '"' || c == '\\')
        o += '\\';
      o += c;
    }
    return o;
  }

  void runModel(const std::string & path, const Options & opt, double & sink)
  {
    pinocchio::Model model;
    pinocchio::urdf::buildModel(path, model, /*verbose=*/false, /*mimic=*/opt.mimic);
    pinocchio::Data data(model);
    const int nq = model.nq, nv = model.nv;
    const std::string name = stem(path);

    std::mt19937_64 rng(opt.seed);
    bool warned = false;
    std::vector<VectorXd> qs, vs, as, taus;
    for (int k = 0; k < opt.states; ++k)
    {
      qs.push_back(randomConfig(model, rng, warned));
      vs.push_back(randomVec(nv, rng));
      as.push_back(randomVec(nv, rng));
      taus.push_back(randomVec(nv, rng));
    }

    // Pinocchio 4.1's ABA does not support mimic joints (the Python bindings
    // raise "This algorithm does not support Joint Mimic type in the model.";
    // in C++ with NDEBUG it just crashes), so ABA is skipped for such models.
    const bool has_mimic = !model.mimicking_joints.empty();

    // Sanity check on state 0: aba(q, v, rnea(q, v, a)) == a, and
    // M(q) a + nle(q, v) == rnea(q, v, a) with the symmetrised CRBA matrix.
    {
      const VectorXd tau = pinocchio::rnea(model, data, Arg(qs[0]), Arg(vs[0]), Arg(as[0]));
      const double aba_err =
        has_mimic ? std::nan("")
                  : (pinocchio::aba(model, data, Arg(qs[0]), Arg(vs[0]), Arg(tau)) - as[0])
                      .cwiseAbs()
                      .maxCoeff();
      pinocchio::crba(model, data, Arg(qs[0]));
      Eigen::MatrixXd M = data.M;
      M.triangularView<Eigen::StrictlyLower>() = M.transpose().triangularView<Eigen::StrictlyLower>();
      const VectorXd zero = VectorXd::Zero(nv);
      const VectorXd nle = pinocchio::rnea(model, data, Arg(qs[0]), Arg(vs[0]), Arg(zero));
      std::fprintf(
        stderr,
        "[%s] %s: nq=%d nv=%d njoints=%d mimic_parse=%d mimicking_joints=%zu | "
        "check |aba(rnea(a))-a|=%.2e |M a+nle-tau|=%.2e\n",
        BENCH_VARIANT, name.c_str(), nq, nv, (int)model.njoints, (int)opt.mimic,
        model.mimicking_joints.size(), aba_err,
        (M * as[0] + nle - tau).cwiseAbs().maxCoeff());
    }

    auto emit = [&](const char * algo, const Timing & t) {
      std::printf(
        "{\"model\": \"%s\", \"algo\": \"%s\", \"dof\": %d, \"ns_per_call\": %.1f, "
        "\"nq\": %d, \"min_ns\": %.1f, \"max_ns\": %.1f, \"reps\": %d, \"calls_per_rep\": %ld, "
        "\"states\": %d, \"variant\": \"%s\", \"mimic\": %s, \"pinocchio\": \"%s\", "
        "\"urdf\": \"%s\"}\n",
        jsonEscape(name).c_str(), algo, nv, t.median, nq, t.min, t.max, opt.reps, t.calls_per_rep,
        opt.states, BENCH_VARIANT, opt.mimic ? "true" : "false", PINOCCHIO_VERSION,
        jsonEscape(path).c_str());
      std::fflush(stdout);
    };

    const pinocchio::JointIndex last = (pinocchio::JointIndex)(model.njoints - 1);
    const int S = opt.states;

    if (wanted(opt, "fk"))
      emit("fk", timeIt([&](int k) {
             pinocchio::forwardKinematics(model, data, Arg(qs[k]));
             return data.oMi[last].translation()[0];
           }, S, opt, sink));

    if (wanted(opt, "jacobians"))
      emit("jacobians", timeIt([&](int k) {
             pinocchio::computeJointJacobians(model, data, Arg(qs[k]));
             return data.J(0, nv - 1);
           }, S, opt, sink));

    if (wanted(opt, "rnea"))
      emit("rnea", timeIt([&](int k) {
             return pinocchio::rnea(model, data, Arg(qs[k]), Arg(vs[k]), Arg(as[k]))[0];
           }, S, opt, sink));

    // crba: Pinocchio fills only the upper triangle of data.M (the strictly
    // lower part is never written). "crba" = crba + copy of the strictly upper
    // triangle into the strictly lower one (full symmetric M, the documented
    // Pinocchio idiom); "crba_upper" = the raw call.
    if (wanted(opt, "crba"))
      emit("crba", timeIt([&](int k) {
             pinocchio::crba(model, data, Arg(qs[k]));
             data.M.triangularView<Eigen::StrictlyLower>() =
               data.M.transpose().triangularView<Eigen::StrictlyLower>();
             return data.M(nv - 1, 0);
           }, S, opt, sink));

    if (wanted(opt, "crba_upper"))
      emit("crba_upper", timeIt([&](int k) {
             pinocchio::crba(model, data, Arg(qs[k]));
             return data.M(0, nv - 1);
           }, S, opt, sink));

    if (wanted(opt, "aba") && has_mimic)
      std::fprintf(stderr, "[%s] %s: aba skipped (mimic joints unsupported by Pinocchio ABA)\n",
                   BENCH_VARIANT, name.c_str());
    else if (wanted(opt, "aba"))
      emit("aba", timeIt([&](int k) {
             return pinocchio::aba(model, data, Arg(qs[k]), Arg(vs[k]), Arg(taus[k]))[0];
           }, S, opt, sink));

    // Derivatives (Carpentier & Mansard 2018): like ABA, Pinocchio 4.1 refuses mimic
    // joints. computeMinverse fills the upper triangle, as crba does.
    if (!has_mimic && wanted(opt, "rnea_derivatives"))
      emit("rnea_derivatives", timeIt([&](int k) {
             pinocchio::computeRNEADerivatives(model, data, Arg(qs[k]), Arg(vs[k]), Arg(as[k]));
             return data.dtau_dq(0, nv - 1) + data.dtau_dv(nv - 1, 0);
           }, S, opt, sink));
    if (!has_mimic && wanted(opt, "aba_derivatives"))
      emit("aba_derivatives", timeIt([&](int k) {
             pinocchio::computeABADerivatives(model, data, Arg(qs[k]), Arg(vs[k]), Arg(taus[k]));
             return data.ddq_dq(0, nv - 1) + data.ddq_dv(nv - 1, 0);
           }, S, opt, sink));
    if (!has_mimic && wanted(opt, "minverse"))
      emit("minverse", timeIt([&](int k) {
             pinocchio::computeMinverse(model, data, Arg(qs[k]));
             return data.Minv(0, nv - 1);
           }, S, opt, sink));
  }

  [[noreturn]] void usage()
  {
    std::fprintf(
      stderr, "usage: bench [--mimic] [--reps R] [--rep-ms T] [--states S] [--seed X] "
              "[--algos fk,jacobians,rnea,crba,crba_upper,aba,rnea_derivatives,\n"
              "aba_derivatives,minverse] robot.urdf [...]\n");
    std::exit(2);
  }
} // namespace

int main(int argc, char ** argv)
{
  Options opt;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc)
        usage();
      return argv[++i];
    };
    if (a == "--mimic")
      opt.mimic = true;
    else if (a == "--reps")
      opt.reps = std::atoi(next().c_str());
    else if (a == "--rep-ms")
      opt.rep_ms = std::atof(next().c_str());
    else if (a == "--states")
      opt.states = std::atoi(next().c_str());
    else if (a == "--seed")
      opt.seed = std::strtoull(next().c_str(), nullptr, 10);
    else if (a == "--algos")
    {
      opt.algos.clear();
      std::stringstream ss(next());
      std::string t;
      while (std::getline(ss, t, ','))
        opt.algos.push_back(t);
    }
    else if (a == "-h" || a == "--help")
      usage();
    else if (!a.empty() && a[0] == '-')
      usage();
    else
      opt.urdfs.push_back(a);
  }
  if (opt.urdfs.empty() || opt.reps < 1 || opt.states < 1 || opt.rep_ms <= 0)
    usage();

  double sink = 0.0;
  int status = 0;
  for (const auto & path : opt.urdfs)
  {
    try
    {
      runModel(path, opt, sink);
    }
    catch (const std::exception & e)
    {
      std::fprintf(stderr, "error: %s: %s\n", path.c_str(), e.what());
      status = 1;
    }
  }
  std::fprintf(stderr, "(sink %g)\n", sink);
  return status;
}
