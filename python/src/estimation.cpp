// Estimation from Python: batch and incremental over a trajectory dict, and the online
// estimator fed sample by sample; results as dicts of NumPy arrays.
#include "common.h"
#include "convert.h"

#include <pushgraph/evaluation/result_json.h>
#include <pushgraph/graph/config.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/incremental.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pushgraph::python {
namespace {

using namespace graph;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

EstimatorConfig ConfigFor(const push::Trajectory& t, const std::string& config_json, bool apply_sigmas) {
  EstimatorConfig cfg;
  if (apply_sigmas && t.measurement_sigmas) cfg = ApplyMeasurementSigmas(cfg, *t.measurement_sigmas);
  if (!config_json.empty()) cfg = ParseEstimatorConfig(config_json, "config", cfg);
  return cfg;
}

struct Online {
  push::Trajectory setup;
  std::unique_ptr<OnlineEstimator> estimator;
};

py::dict StateToDict(const StateEstimate& s) {
  py::dict d;
  d["t"] = s.t;
  d["object_pose"] = py::make_tuple(s.object_pose.x, s.object_pose.y, s.object_pose.theta);
  d["finger_pose"] = py::make_tuple(s.finger_pose.x, s.finger_pose.y, s.finger_pose.theta);
  d["contact"] = s.contact ? py::object(py::make_tuple(s.contact->x(), s.contact->y())) : py::none();
  d["force"] = s.force ? py::object(py::make_tuple(s.force->x(), s.force->y())) : py::none();
  for (const FingerPoseEstimate& f : s.other_fingers) {  // several fingers: finger k's pose
    d[("finger" + std::to_string(f.finger) + "_pose").c_str()] = py::make_tuple(f.pose.x, f.pose.y, f.pose.theta);
  }
  // Every contact (a wedged finger's two, or one per finger that touches), with its finger.
  py::list contacts;
  for (const ContactEstimate& c : s.contacts) {
    py::dict e;
    e["finger"] = c.finger;
    e["point"] = py::make_tuple(c.point.x(), c.point.y());
    e["force"] = c.force ? py::object(py::make_tuple(c.force->x(), c.force->y())) : py::none();
    contacts.append(e);
  }
  d["contacts"] = contacts;
  return d;
}

}  // namespace

py::dict ResultToDict(const EstimationResult& r) {
  const py::ssize_t n = static_cast<py::ssize_t>(r.states.size());
  py::array_t<double> t = NewArray({n}), object = NewArray({n, 3}), finger = NewArray({n, 3}), contact = NewArray({n, 2}),
                      force = NewArray({n, 2}), object_cov = NewArray({n, 3, 3}), finger_cov = NewArray({n, 3, 3}),
                      contact_cov = NewArray({n, 2, 2}), force_cov = NewArray({n, 2, 2});
  // Two-contact states (a finger wedged in a notch): the second contact and each one's force; in a
  // two-finger push the second contact is finger 1's, and finger 1 has its own pose.
  py::array_t<double> second = NewArray({n, 2}), second_cov = NewArray({n, 2, 2}), forces = NewArray({n, 2, 2});
  int fingers = 1;
  for (const StateEstimate& s : r.states) fingers = std::max(fingers, 1 + static_cast<int>(s.other_fingers.size()));
  const bool two_fingers = fingers > 1;
  // Fingers 1, 2, ...: each one's pose, contact point and force (NaN where it does not touch).
  std::vector<py::array_t<double>> finger_k(fingers), finger_k_cov(fingers), contact_k(fingers), force_k(fingers),
      contact_k_cov(fingers), force_k_cov(fingers);
  for (int k = 1; k < fingers; ++k) {
    finger_k[k] = NewArray({n, 3});
    finger_k_cov[k] = NewArray({n, 3, 3});
    contact_k[k] = NewArray({n, 2});
    force_k[k] = NewArray({n, 2});
    contact_k_cov[k] = NewArray({n, 2, 2});
    force_k_cov[k] = NewArray({n, 2, 2});
  }
  auto put_cov = [](double* out, const auto& cov, int dim) {
    for (int k = 0; k < dim * dim; ++k) out[k] = cov ? (*cov)(k / dim, k % dim) : kNaN;
  };
  for (py::ssize_t i = 0; i < n; ++i) {
    const StateEstimate& s = r.states[i];
    t.mutable_data()[i] = s.t;
    for (int k = 0; k < 3; ++k) {
      object.mutable_data()[3 * i + k] = s.object_pose.vector()[k];
      finger.mutable_data()[3 * i + k] = s.finger_pose.vector()[k];
    }
    for (int k = 0; k < 2; ++k) {
      contact.mutable_data()[2 * i + k] = s.contact ? (*s.contact)[k] : kNaN;
      force.mutable_data()[2 * i + k] = s.force ? (*s.force)[k] : kNaN;
    }
    put_cov(object_cov.mutable_data() + 9 * i, s.object_pose_cov, 3);
    put_cov(finger_cov.mutable_data() + 9 * i, s.finger_pose_cov, 3);
    put_cov(contact_cov.mutable_data() + 4 * i, s.contact_cov, 2);
    put_cov(force_cov.mutable_data() + 4 * i, s.force_cov, 2);
    // The first and the second contact: of a wedged finger its two; of two fingers finger 0's
    // and finger 1's (either may be absent).
    const ContactEstimate* first = nullptr;
    const ContactEstimate* other = nullptr;
    if (two_fingers) {
      for (const ContactEstimate& c : s.contacts) {
        if (c.finger == 0) first = &c;
        if (c.finger == 1) other = &c;
      }
    } else if (s.contacts.size() == 2) {
      first = &s.contacts[0];
      other = &s.contacts[1];
    }
    const ContactEstimate* both[2] = {first, other};
    for (int k = 0; k < 2; ++k) {
      second.mutable_data()[2 * i + k] = other ? other->point[k] : kNaN;
      for (int c = 0; c < 2; ++c)
        forces.mutable_data()[4 * i + 2 * c + k] = both[c] && both[c]->force ? (*both[c]->force)[k] : kNaN;
    }
    put_cov(second_cov.mutable_data() + 4 * i, other ? other->point_cov : std::nullopt, 2);
    for (int f = 1; f < fingers; ++f) {
      const FingerPoseEstimate* pose = nullptr;
      for (const FingerPoseEstimate& e : s.other_fingers) pose = e.finger == f ? &e : pose;
      const ContactEstimate* touch = nullptr;  // its first contact
      for (const ContactEstimate& c : s.contacts) touch = c.finger == f && touch == nullptr ? &c : touch;
      for (int k = 0; k < 3; ++k) finger_k[f].mutable_data()[3 * i + k] = pose ? pose->pose.vector()[k] : kNaN;
      put_cov(finger_k_cov[f].mutable_data() + 9 * i, pose ? pose->pose_cov : std::nullopt, 3);
      for (int k = 0; k < 2; ++k) {
        contact_k[f].mutable_data()[2 * i + k] = touch ? touch->point[k] : kNaN;
        force_k[f].mutable_data()[2 * i + k] = touch && touch->force ? (*touch->force)[k] : kNaN;
      }
      put_cov(contact_k_cov[f].mutable_data() + 4 * i, touch ? touch->point_cov : std::nullopt, 2);
      put_cov(force_k_cov[f].mutable_data() + 4 * i, touch ? touch->force_cov : std::nullopt, 2);
    }
  }
  py::dict d;
  d["model"] = ModelName(r.model);
  d["mode"] = ModeName(r.mode);
  d["t"] = t;
  d["object_pose"] = object;
  d["finger_pose"] = finger;
  d["contact"] = contact;
  d["force"] = force;
  d["object_pose_cov"] = object_cov;
  d["finger_pose_cov"] = finger_cov;
  d["contact_cov"] = contact_cov;
  d["force_cov"] = force_cov;
  d["second_contact"] = second;
  d["second_contact_cov"] = second_cov;
  d["contact_forces"] = forces;
  for (int k = 1; k < fingers; ++k) {
    const std::string f = "finger" + std::to_string(k);
    d[(f + "_pose").c_str()] = finger_k[k];
    d[(f + "_pose_cov").c_str()] = finger_k_cov[k];
    d[(f + "_contact").c_str()] = contact_k[k];
    d[(f + "_force").c_str()] = force_k[k];
    d[(f + "_contact_cov").c_str()] = contact_k_cov[k];
    d[(f + "_force_cov").c_str()] = force_k_cov[k];
  }
  py::dict metrics;
  for (const auto& [k, v] : r.metrics) metrics[k.c_str()] = v;
  d["metrics"] = metrics;
  d["warnings"] = TextList(r.warnings);
  py::dict solver;
  solver["name"] = r.solver.name;
  solver["iterations"] = r.solver.iterations;
  solver["time_s"] = r.solver.time_s;
  solver["final_cost"] = r.solver.final_cost;
  solver["updates"] = r.solver.updates;
  solver["mean_update_time_s"] = r.solver.mean_update_time_s;
  solver["max_update_time_s"] = r.solver.max_update_time_s;
  solver["covariance"] = r.solver.covariance_status;
  py::array_t<double> updates = NewArray({static_cast<py::ssize_t>(r.solver.update_times_s.size())});
  std::copy(r.solver.update_times_s.begin(), r.solver.update_times_s.end(), updates.mutable_data());
  solver["update_times_s"] = updates;
  d["solver"] = solver;
  d["c"] = r.c ? py::object(py::float_(*r.c)) : py::none();
  d["c_sigma"] = r.c_sigma ? py::object(py::float_(*r.c_sigma)) : py::none();
  d["mu"] = r.mu ? py::object(py::float_(*r.mu)) : py::none();
  d["mu_sigma"] = r.mu_sigma ? py::object(py::float_(*r.mu_sigma)) : py::none();
  // RESULT.json's parameters (the shape transform applied, c, mu), shape check and
  // self-diagnosis, with the file's keys: a Python caller could not see which transform an
  // aligned estimate used but by parsing the warning.
  const py::dict summary = py::module_::import("json").attr("loads")(evaluation::ResultSummaryJson(r));
  for (const char* key : {"parameters", "shape", "diagnostics"})
    d[key] = summary.contains(key) ? py::object(summary[key]) : py::object(py::none());
  return d;
}

void RegisterEstimation(py::module_& m) {
  using namespace pybind11::literals;
  m.def(
      "_estimate",
      [](const py::handle& trajectory, const std::string& model, const std::string& mode, const std::string& config_json,
         bool apply_sigmas) {
        const push::Trajectory t = TrajectoryFromDict(trajectory);
        const Model parsed_model = ParseModel(model);
        const Mode parsed_mode = ParseMode(mode);
        const EstimatorConfig cfg = ConfigFor(t, config_json, apply_sigmas);
        EstimationResult r;
        {
          py::gil_scoped_release release;
          r = Estimate(t, parsed_model, parsed_mode, cfg);
        }
        return ResultToDict(r);
      },
      "trajectory"_a, "model"_a, "mode"_a, "config_json"_a, "apply_measurement_sigmas"_a);

  py::class_<Online>(m, "_OnlineEstimator")
      .def(py::init([](const py::handle& setup, const std::string& model, const std::string& config_json, bool contact_point,
                       bool force, double max_latency) {
             auto o = std::make_unique<Online>();
             o->setup = TrajectoryFromDict(setup);
             OnlineStreams streams;
             streams.contact_point = contact_point;
             streams.force = force;
             streams.max_latency = max_latency;
             o->estimator = std::make_unique<OnlineEstimator>(o->setup, ParseModel(model),
                                                              ConfigFor(o->setup, config_json, true), streams);
             return o;
           }),
           "setup"_a, "model"_a, "config_json"_a, "contact_point"_a, "force"_a, "max_latency"_a)
      .def("add_object_pose",
           [](Online& o, double t, const py::handle& pose) { return o.estimator->AddObjectPose(t, ToPose(pose, "pose", false)); })
      .def("add_finger_pose",
           [](Online& o, double t, const py::handle& pose, int finger) {
             return o.estimator->AddFingerPose(t, finger, ToPose(pose, "pose", false));
           })
      .def("add_contact_point",
           [](Online& o, double t, const py::handle& p, int finger) {
             return o.estimator->AddContactPoint(t, finger, ToVec2(p, "point", false));
           })
      .def("add_force", [](Online& o, double t, const py::handle& f, int finger) {
        return o.estimator->AddForce(t, finger, ToVec2(f, "force", false));
      })
      .def("update_due", [](const Online& o) { return o.estimator->UpdateDue(); })
      .def("update",
           [](Online& o, double until) {
             py::gil_scoped_release release;
             return o.estimator->Update(until);
           },
           "until"_a = INFINITY)
      .def("latest_state", [](const Online& o) { return StateToDict(o.estimator->LatestState()); })
      .def_property_readonly("dropped_late_samples", [](const Online& o) { return o.estimator->DroppedLateSamples(); })
      .def_property_readonly("dropped_faulty_samples", [](const Online& o) { return o.estimator->DroppedFaultySamples(); })
      .def("warnings", [](const Online& o) { return o.estimator->Warnings(); })
      .def("finish", [](Online& o) {
        EstimationResult r;
        {
          py::gil_scoped_release release;
          r = o.estimator->Finish();
        }
        return ResultToDict(r);
      });
}

}  // namespace pushgraph::python
