// Minimal checking helpers for the core tests (no test framework is needed on the GPU host).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

namespace mpm_test
{
  inline int &failures()
  {
    static int n = 0;
    return n;
  }

  inline void check(const bool ok, const char *what, const double value = 0, const double limit = 0)
  {
    if (!ok)
      {
        ++failures();
        std::printf("FAILED: %s (value %.6e, limit %.6e)\n", what, value, limit);
      }
  }

  inline void check_below(const double value, const double limit, const char *what)
  {
    check(std::isfinite(value) && value <= limit, what, value, limit);
  }

  // True if work() throws an exception whose message contains text; deal.II folds messages over
  // lines, so runs of white space compare as one space. Prints the message otherwise.
  template <typename Work>
  bool throws_naming(Work &&work, const std::string &text)
  {
    try
      {
        work();
      }
    catch (const std::exception &e)
      {
        std::string message;
        for (const char c : std::string(e.what()))
          if (c != ' ' && c != '\n' && c != '\t' && c != '\r')
            message += c;
          else if (!message.empty() && message.back() != ' ')
            message += ' ';
        const bool named = message.find(text) != std::string::npos;
        if (!named)
          std::printf("message without '%s': %s\n", text.c_str(), e.what());
        return named;
      }
    std::printf("no exception (expected one naming '%s')\n", text.c_str());
    return false;
  }

  inline int finish(const char *name)
  {
    if (failures() == 0)
      std::printf("%s: all checks passed\n", name);
    else
      std::printf("%s: %d checks failed\n", name, failures());
    return failures() == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
  }
} // namespace mpm_test
