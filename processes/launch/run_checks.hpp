// What makes a run of the graph fail besides a process dying: the input log (damaged, or nothing
// readable in it: lcm-logplayer stops silently at damage), and the monitor's verdict on the run
// (losses, stalls, rejected messages: monitor.json's "ok" and "problems"), and the run log's
// recorder (traverse-record's last line: messages it had to drop, writes that failed).
#pragma once

#include <string>
#include <vector>

namespace traverse::launch {

// Problems of the input log, one sentence each (empty when every byte is a readable event).
std::vector<std::string> input_log_problems(const std::string& path);

// The monitor's verdict from its summary file: its problems, or one saying the file is missing
// or has no verdict. Empty when the run is ok.
std::vector<std::string> monitor_problems(const std::string& monitor_json);

// The recorder's summary (the last line of its output, `recorder_out`): a problem for messages its
// receive queue dropped or events it could not write (the run log lacks them), or one saying
// the summary is missing (the recorder did not end cleanly: the log reads up to its last flush).
std::vector<std::string> recorder_problems(const std::string& recorder_out);

// net.core.rmem_max against the receive buffer a run's LCM URL asks for [bytes]: raises it when
// `raise` (as root; system-wide, so only when told), otherwise says what it means. Returns the
// sentence printed, empty when nothing needed saying.
std::string check_rmem_max(long wanted, bool raise);

}  // namespace traverse::launch
