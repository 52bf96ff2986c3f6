// BenchReport: header (machine, Embree, parameters), tables, notes; files
// through the atomic writer.
#include "bench/report/report_bench.h"

#include <ctime>
#include <filesystem>
#include <ostream>
#include <stdexcept>

#include "bench/report/machine_info.h"

namespace hprt::bench {

BenchReport::BenchReport(std::string bench, std::string title, const BenchOptions& options)
    : bench_(std::move(bench)), title_(std::move(title)), options_(options) {
  params_["quick"] = options.quick;
}

void BenchReport::set_param(const std::string& key, nlohmann::json value) {
  params_[key] = std::move(value);
}

Table& BenchReport::add_table(const std::string& name, const std::string& title, Table table) {
  tables_.push_back(Named{name, title, std::move(table)});
  return tables_.back().table;
}

Table& BenchReport::table(const std::string& name) {
  for (auto& t : tables_)
    if (t.name == name) return t.table;
  throw std::out_of_range("report has no table '" + name + "'");
}

namespace {
std::string param_text(const nlohmann::json& v) {
  return v.is_string() ? v.get<std::string>() : v.dump();
}
std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}
}  // namespace

void BenchReport::write_markdown(std::ostream& out) const {
  out << "## " << title_ << "\n\n" << machine_markdown(machine_info());
  for (auto it = params_.begin(); it != params_.end(); ++it)
    out << "- " << it.key() << ": " << param_text(it.value()) << "\n";
  out << "\n";
  for (const auto& t : tables_) {
    out << "### " << t.title << "\n\n";
    t.table.write_markdown(out);
    out << "\n";
  }
  for (const auto& n : notes_) out << "- " << n << "\n";
  if (!notes_.empty()) out << "\n";
}

nlohmann::json BenchReport::to_json() const {
  nlohmann::json j;
  j["bench"] = bench_;
  j["title"] = title_;
  j["date_utc"] = utc_now();
  j["machine"] = hprt::bench::to_json(machine_info());
  j["params"] = params_;
  nlohmann::json tables = nlohmann::json::object();
  for (const auto& t : tables_) {
    nlohmann::json tj = t.table.to_json();
    tj["title"] = t.title;
    tables[t.name] = std::move(tj);
  }
  j["tables"] = std::move(tables);
  j["notes"] = notes_;
  j["files"] = files_;
  return j;
}

std::vector<std::string> BenchReport::write_files() const {
  std::vector<std::string> written;
  if (options_.out_dir.empty()) return written;
  const std::filesystem::path dir(options_.out_dir);
  for (const auto& t : tables_) {
    const std::string path = (dir / (bench_ + "_" + t.name + ".csv")).string();
    t.table.write_csv(path);
    written.push_back(path);
  }
  const std::string json_path = (dir / (bench_ + ".json")).string();
  write_text_atomic(json_path, to_json().dump(2) + "\n");
  written.push_back(json_path);
  return written;
}

}  // namespace hprt::bench
