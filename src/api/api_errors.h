// The public API's one error translation: hprt's InputError (and its
// OptionError) become hprt::api::Error with the same one-line message.
#pragma once

#include <hprt/hprt.h>

#include <utility>

#include "core/error.h"

namespace hprt::api {

template <typename F>
decltype(auto) translate_errors(F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const InputError& e) {
    throw Error(e.what());
  }
}

}  // namespace hprt::api
