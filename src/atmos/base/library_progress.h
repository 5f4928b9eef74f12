// atmos: whether the library's own long work (precomputations) may show a
// progress bar (base/progress.h) on stderr. Off by default (library users and
// tests stay silent); the CLI turns it on around its work unless --quiet. The
// bar itself still prints only on a terminal and after about a second.
#pragma once

namespace atmos {

bool LibraryProgressEnabled();

// Sets the switch for its lifetime, then restores the previous value.
class LibraryProgressScope {
  public:
    explicit LibraryProgressScope(bool enabled);
    ~LibraryProgressScope();
    LibraryProgressScope(const LibraryProgressScope&) = delete;
    LibraryProgressScope& operator=(const LibraryProgressScope&) = delete;

  private:
    bool previous_;
};

}  // namespace atmos
