// A benchmark result table: named columns, rows of cells (text, integer or
// number, empty allowed), written as a Markdown table to a stream and as CSV
// or JSON to files through the atomic writer (whole file or nothing).
#pragma once

#include <concepts>
#include <cstdint>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

namespace hprt::bench {

// One cell: empty (printed "–" in Markdown, empty in CSV, null in JSON);
// a bool is "yes"/"no" in Markdown, true/false in CSV and JSON.
using Cell = std::variant<std::monostate, std::string, int64_t, double, bool>;

struct Column {
  std::string name;
  int decimals = 2;  // Markdown display of double cells; CSV/JSON keep full precision
};

class Table {
 public:
  Table() = default;
  explicit Table(std::vector<Column> columns);
  // Convenience: names only, doubles shown with 2 decimals.
  static Table with_names(const std::vector<std::string>& names);

  const std::vector<Column>& columns() const { return columns_; }
  size_t row_count() const { return rows_.size(); }
  const std::vector<Cell>& row(size_t i) const { return rows_[i]; }
  // Index of a column by name; throws std::out_of_range when absent.
  size_t column_index(const std::string& name) const;

  // Appends a row with one cell per column (throws std::invalid_argument
  // otherwise).
  void add_row(std::vector<Cell> cells);

  // Builds a row cell by cell by column name; unset cells stay empty.
  class RowBuilder {
   public:
    RowBuilder& set_cell(const std::string& column, Cell value);
    RowBuilder& set(const std::string& column, const std::string& text) {
      return set_cell(column, Cell(text));
    }
    RowBuilder& set(const std::string& column, const char* text) {
      return set_cell(column, Cell(std::string(text)));
    }
    RowBuilder& set(const std::string& column, double value) {
      return set_cell(column, Cell(value));
    }
    RowBuilder& set(const std::string& column, float value) {
      return set_cell(column, Cell(double(value)));
    }
    RowBuilder& set(const std::string& column, bool value) { return set_cell(column, Cell(value)); }
    template <std::integral T>
    RowBuilder& set(const std::string& column, T value) {
      return set_cell(column, Cell(int64_t(value)));
    }

   private:
    friend class Table;
    RowBuilder(Table& t, size_t row) : table_(t), row_(row) {}
    Table& table_;
    size_t row_;
  };
  RowBuilder new_row();
  RowBuilder edit_row(size_t i);  // set cells of an existing row (throws std::out_of_range)

  // Notes printed under the Markdown table ("> note") and stored in JSON.
  void add_note(std::string note) { notes_.push_back(std::move(note)); }
  const std::vector<std::string>& notes() const { return notes_; }

  void write_markdown(std::ostream& out) const;
  std::string markdown() const;
  std::string csv() const;  // header line + one line per row, RFC 4180 quoting
  // {"columns": [...], "rows": [{column: value, ...}, ...], "notes": [...]}
  nlohmann::json to_json() const;

  // Atomic file writes; throw InputError naming the path when it cannot be written.
  void write_csv(const std::string& path) const;
  void write_json(const std::string& path, const nlohmann::json& extra = {}) const;

 private:
  std::vector<Column> columns_;
  std::vector<std::vector<Cell>> rows_;
  std::vector<std::string> notes_;
};

// Cell as text: Markdown style when `decimals >= 0`, full precision (%.9g) otherwise.
std::string format_cell(const Cell& cell, int decimals);
nlohmann::json cell_to_json(const Cell& cell);

// Writes `text` to `path` atomically (io/files/atomic_file.h).
void write_text_atomic(const std::string& path, const std::string& text);

}  // namespace hprt::bench
