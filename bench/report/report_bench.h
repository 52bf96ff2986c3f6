// A whole benchmark report: the machine, the run's parameters (threads,
// repetitions, quick or full), one or more named tables with notes. Printed
// as Markdown; with --out written as <bench>_<table>.csv per table and one
// <bench>.json holding everything.
#pragma once

#include <deque>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/bench_options.h"
#include "bench/report/report_table.h"

namespace hprt::bench {

class BenchReport {
 public:
  // `bench` names the files ("build" -> build_<table>.csv, build.json).
  BenchReport(std::string bench, std::string title, const BenchOptions& options);

  // Run parameters shown in the header and stored in the JSON ("threads",
  // "repetitions", ...).
  void set_param(const std::string& key, nlohmann::json value);
  // Adds a table; `name` is its file stem, `title` its Markdown heading.
  Table& add_table(const std::string& name, const std::string& title, Table table);
  Table& table(const std::string& name);
  void add_note(std::string note) { notes_.push_back(std::move(note)); }
  // A file the bench wrote itself into out_dir (a plot), listed in the JSON.
  void add_file(std::string path) { files_.push_back(std::move(path)); }

  void write_markdown(std::ostream& out) const;
  nlohmann::json to_json() const;
  // Writes the CSV and JSON files into options.out_dir (no-op when empty);
  // returns the paths written.
  std::vector<std::string> write_files() const;

  const BenchOptions& options() const { return options_; }

 private:
  struct Named {
    std::string name, title;
    Table table;
  };
  std::string bench_, title_;
  BenchOptions options_;
  nlohmann::json params_ = nlohmann::json::object();
  std::deque<Named> tables_;  // deque: add_table() references stay valid
  std::vector<std::string> notes_;
  std::vector<std::string> files_;
};

}  // namespace hprt::bench
