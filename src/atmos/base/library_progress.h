// atmos: whether the library's own long work (precomputations) may show a
// progress bar (base/progress.h) on stderr. Off by default (library users and
// tests stay silent); the CLI turns it on around its work unless --quiet. The
// bar itself still prints only on a terminal and after about a second.
#pragma once

#include "base/non_copyable.h"

namespace atmos {

bool LibraryProgressEnabled();

// Sets the switch for its lifetime, then restores the previous value.
class LibraryProgressScope : private NonCopyable {
  public:
    explicit LibraryProgressScope(bool enabled);
    ~LibraryProgressScope();

  private:
    bool previous_;
};

}  // namespace atmos
