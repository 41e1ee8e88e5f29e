// pushgraph.evaluate: the paper's evaluation protocols (io/evaluation.h, `pushgraph evaluate`)
// over recordings, trajectory files and simulated pushes; the tables as lists of dicts.
#include "common.h"

#include <pushgraph/evaluation/evaluation.h>

#include <thread>

namespace pushgraph::python {

void RegisterEvaluation(py::module_& m) {
  using namespace pybind11::literals;
  m.def(
      "_evaluate",
      [](const std::vector<std::string>& inputs, const std::string& protocols, int simulate, const py::object& sim_object,
         const py::object& sim_finger, double sim_mass, double sim_mu, double sim_mu_contact, std::uint64_t seed, int jobs,
         const std::string& mesh_dir, const std::string& estimator_json) {
        evaluation::EvaluationOptions options;
        options.protocols = evaluation::ParseProtocols(protocols);
        options.seed = seed;
        options.mesh_dir = mesh_dir;
        if (!estimator_json.empty()) options.estimator = graph::ParseEstimatorConfig(estimator_json, "estimator_config");
        if (simulate < 0) throw py::value_error("simulate: must be >= 0");
        options.simulation.count = simulate;
        if (simulate > 0) {
          if (sim_object.is_none() || sim_finger.is_none()) throw py::value_error("simulate > 0 needs sim_object and sim_finger shapes");
          options.simulation.object.shape = sim_object.cast<geometry::Shape>();
          options.simulation.finger.shape = sim_finger.cast<geometry::Shape>();
          if (!(sim_mass > 0.0) || !(sim_mu > 0.0) || !(sim_mu_contact >= 0.0)) {
            throw py::value_error("sim_mass and sim_mu must be > 0, sim_mu_contact >= 0");
          }
          options.simulation.object.mass = sim_mass;
          options.simulation.object.mu_surface = sim_mu;
          options.simulation.finger.mu_contact = sim_mu_contact;
          options.simulation.name = "sim";
        }
        std::vector<evaluation::EvaluationRow> rows;
        std::vector<std::string> notes;
        {
          py::gil_scoped_release release;
          const std::vector<std::string> files = inputs.empty() ? std::vector<std::string>{} : evaluation::ExpandInputs(inputs);
          std::vector<evaluation::EvaluationItem> items = evaluation::PlanEvaluation(files, options);
          if (items.empty()) throw graph::GraphError("evaluate: nothing to evaluate: give inputs or simulate > 0");
          notes = evaluation::RegisterGroups(items, options);
          rows = evaluation::RunEvaluation(items, options, jobs);
        }
        py::list tables;
        for (const evaluation::Table& t : evaluation::MakeTables(rows, options.SettingsJson())) {
          py::list table_rows;
          for (const auto& r : t.rows) {
            py::dict row;
            for (std::size_t c = 0; c < t.columns.size() && c < r.size(); ++c) row[t.columns[c].c_str()] = r[c];
            table_rows.append(row);
          }
          py::dict table;
          table["id"] = t.id;
          table["title"] = t.title;
          table["columns"] = t.columns;
          table["rows"] = table_rows;
          table["notes"] = TextList(t.notes);
          tables.append(table);
        }
        py::list trajectories;
        for (const evaluation::EvaluationRow& r : rows) {
          py::dict d;
          d["name"] = r.name;
          d["group"] = r.group;
          d["error"] = r.error;
          d["stats"] = r.stats;
          d["notes"] = TextList(r.notes);
          trajectories.append(d);
        }
        py::dict out;
        out["tables"] = tables;
        out["trajectories"] = trajectories;
        out["notes"] = TextList(notes);
        return out;
      },
      "inputs"_a, "protocols"_a, "simulate"_a, "sim_object"_a, "sim_finger"_a, "sim_mass"_a, "sim_mu"_a,
      "sim_mu_contact"_a, "seed"_a, "jobs"_a, "mesh_dir"_a, "estimator_json"_a);
}

}  // namespace pushgraph::python
