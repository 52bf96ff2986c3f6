// Table rendering: Markdown (aligned, numbers right-aligned), CSV (RFC 4180)
// and JSON (one object per row keyed by column name).
#include "bench/report/report_table.h"

#include <cmath>
#include <cstdio>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "io/files/atomic_file.h"

namespace hprt::bench {

Table::Table(std::vector<Column> columns) : columns_(std::move(columns)) {}

Table Table::with_names(const std::vector<std::string>& names) {
  std::vector<Column> cols;
  for (const auto& n : names) cols.push_back(Column{n, 2});
  return Table(std::move(cols));
}

size_t Table::column_index(const std::string& name) const {
  for (size_t i = 0; i < columns_.size(); ++i)
    if (columns_[i].name == name) return i;
  throw std::out_of_range("table has no column '" + name + "'");
}

void Table::add_row(std::vector<Cell> cells) {
  if (cells.size() != columns_.size())
    throw std::invalid_argument("table row has " + std::to_string(cells.size()) + " cells for " +
                                std::to_string(columns_.size()) + " columns");
  rows_.push_back(std::move(cells));
}

Table::RowBuilder Table::new_row() {
  rows_.emplace_back(columns_.size());
  return RowBuilder(*this, rows_.size() - 1);
}

Table::RowBuilder Table::edit_row(size_t i) {
  if (i >= rows_.size()) throw std::out_of_range("table has no row " + std::to_string(i));
  return RowBuilder(*this, i);
}

Table::RowBuilder& Table::RowBuilder::set_cell(const std::string& column, Cell value) {
  table_.rows_[row_][table_.column_index(column)] = std::move(value);
  return *this;
}

std::string format_cell(const Cell& cell, int decimals) {
  if (std::holds_alternative<std::monostate>(cell)) return decimals >= 0 ? "–" : "";
  if (const auto* s = std::get_if<std::string>(&cell)) return *s;
  if (const auto* i = std::get_if<int64_t>(&cell)) return std::to_string(*i);
  if (const auto* b = std::get_if<bool>(&cell))
    return decimals >= 0 ? (*b ? "yes" : "no") : (*b ? "true" : "false");
  const double d = std::get<double>(cell);
  if (std::isnan(d)) return decimals >= 0 ? "–" : "";
  if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
  char buf[64];
  if (decimals >= 0)
    std::snprintf(buf, sizeof buf, "%.*f", decimals, d);
  else
    std::snprintf(buf, sizeof buf, "%.9g", d);
  return buf;
}

nlohmann::json cell_to_json(const Cell& cell) {
  if (const auto* s = std::get_if<std::string>(&cell)) return *s;
  if (const auto* i = std::get_if<int64_t>(&cell)) return *i;
  if (const auto* b = std::get_if<bool>(&cell)) return *b;
  if (const auto* d = std::get_if<double>(&cell)) {
    if (std::isfinite(*d)) return *d;
    if (std::isinf(*d)) return *d > 0 ? "inf" : "-inf";
  }
  return nullptr;
}

namespace {
bool is_numeric(const Cell& c) {
  return std::holds_alternative<int64_t>(c) || std::holds_alternative<double>(c);
}
// Display width in code points (cells may hold UTF-8 such as "–" or "×").
size_t display_width(const std::string& s) {
  size_t n = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++n;
  return n;
}
std::string escape_markdown(std::string s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}
}  // namespace

void Table::write_markdown(std::ostream& out) const {
  const size_t nc = columns_.size();
  std::vector<std::vector<std::string>> text(rows_.size(), std::vector<std::string>(nc));
  std::vector<size_t> width(nc, 3);
  std::vector<bool> numeric(nc, false);
  for (size_t c = 0; c < nc; ++c) {
    width[c] = std::max(width[c], display_width(escape_markdown(columns_[c].name)));
    for (const auto& row : rows_)
      if (is_numeric(row[c])) numeric[c] = true;
  }
  for (size_t r = 0; r < rows_.size(); ++r)
    for (size_t c = 0; c < nc; ++c) {
      text[r][c] = escape_markdown(format_cell(rows_[r][c], std::max(0, columns_[c].decimals)));
      width[c] = std::max(width[c], display_width(text[r][c]));
    }
  auto pad = [&](const std::string& s, size_t c, bool right) {
    const std::string fill(width[c] - display_width(s), ' ');
    return right ? fill + s : s + fill;
  };
  out << '|';
  for (size_t c = 0; c < nc; ++c)
    out << ' ' << pad(escape_markdown(columns_[c].name), c, numeric[c]) << " |";
  out << "\n|";
  for (size_t c = 0; c < nc; ++c)
    out << (numeric[c] ? std::string(width[c] + 1, '-') + ":|"
                       : std::string(width[c] + 2, '-') + "|");
  out << '\n';
  for (size_t r = 0; r < rows_.size(); ++r) {
    out << '|';
    for (size_t c = 0; c < nc; ++c) out << ' ' << pad(text[r][c], c, numeric[c]) << " |";
    out << '\n';
  }
  if (!notes_.empty()) {
    out << '\n';
    for (const auto& n : notes_) out << "> " << n << "\n";
  }
}

std::string Table::markdown() const {
  std::ostringstream s;
  write_markdown(s);
  return s.str();
}

namespace {
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}
}  // namespace

std::string Table::csv() const {
  std::string out;
  for (size_t c = 0; c < columns_.size(); ++c) {
    if (c) out += ',';
    out += csv_field(columns_[c].name);
  }
  out += '\n';
  for (const auto& row : rows_) {
    for (size_t c = 0; c < columns_.size(); ++c) {
      if (c) out += ',';
      out += csv_field(format_cell(row[c], -1));
    }
    out += '\n';
  }
  return out;
}

nlohmann::json Table::to_json() const {
  nlohmann::json cols = nlohmann::json::array();
  for (const auto& c : columns_) cols.push_back(c.name);
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : rows_) {
    nlohmann::json obj = nlohmann::json::object();
    for (size_t c = 0; c < columns_.size(); ++c) obj[columns_[c].name] = cell_to_json(row[c]);
    rows.push_back(std::move(obj));
  }
  return {{"columns", cols}, {"rows", rows}, {"notes", notes_}};
}

void write_text_atomic(const std::string& path, const std::string& text) {
  write_file_atomic(path, text.data(), text.size());
}

void Table::write_csv(const std::string& path) const { write_text_atomic(path, csv()); }

void Table::write_json(const std::string& path, const nlohmann::json& extra) const {
  nlohmann::json j = to_json();
  if (extra.is_object())
    for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
  write_text_atomic(path, j.dump(2) + "\n");
}

}  // namespace hprt::bench
