#pragma once
// Interruption of a run: the first SIGINT (Ctrl-C) or SIGTERM asks the run to stop once its
// current step is done (it then writes a snapshot, a checkpoint and its summary); a second one
// stops the program at once (the default action, restored by the first).

namespace gpa::app {

class StopRequests {
public:
    // Installs the handlers; the destructor puts back the ones that were there.
    StopRequests();
    ~StopRequests();
    StopRequests(const StopRequests&) = delete;
    StopRequests& operator=(const StopRequests&) = delete;

    // The signal that asked to stop (SIGINT or SIGTERM), or 0.
    static int requested();
};

}  // namespace gpa::app
