// atmos: stop signals during long work (issue 18 item 10, issue 39 item 1).
//
// While a StopSignalScope is active, SIGINT, SIGTERM and SIGHUP are only
// recorded (and their default action restored: a second signal ends the
// process at once); long steps poll StopSignalReceived() between bands of
// work of about a second and stop with one clear error, so a signal acts
// within about a second whatever the size of the work.
#pragma once

#include <signal.h>

#include "base/non_copyable.h"

namespace atmos {

// The signal recorded by the active StopSignalScope, or 0.
int StopSignalReceived();
// "SIGINT", "SIGTERM" or "SIGHUP".
const char* StopSignalName(int signal_number);

class StopSignalScope : private NonCopyable {
  public:
    explicit StopSignalScope(bool active);
    ~StopSignalScope();
    int Received() const { return active_ ? StopSignalReceived() : 0; }

  private:
    bool active_;
    struct sigaction old_int_ {};
    struct sigaction old_term_ {};
    struct sigaction old_hup_ {};
};

}  // namespace atmos
