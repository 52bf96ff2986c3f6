// InputError's message stays one line whatever the text it quotes (a file's
// bytes, a JSON key, a plugin's name): control characters become escapes.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace hprt {
namespace {

TEST(InputError, ControlCharactersAreEscaped) {
  EXPECT_EQ(one_line("plain text: 1.5"), "plain text: 1.5");
  EXPECT_EQ(one_line(std::string("a\nb\rc\td\x1b[0m\x7f") + '\0' + "e"),
            "a\\nb\\rc\\td\\x1b[0m\\x7f\\x00e");
  EXPECT_EQ(one_line("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 is text, not control
  const InputError e("scene.json", "unknown field 'bad\nkey'");
  EXPECT_STREQ(e.what(), "scene.json: unknown field 'bad\\nkey'");
  const OptionError o("leaf_size", "must be\npositive");
  EXPECT_STREQ(o.problem(), "must be\\npositive");
}

}  // namespace
}  // namespace hprt
