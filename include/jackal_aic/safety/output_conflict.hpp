#pragma once
/**
 * \file output_conflict.hpp
 * \brief One publisher per command topic, without ROS: the decision whether the node's output
 *        topic has another publisher, from the publisher lists the node polls from the ROS
 *        master (src/ros/publisher_watch.cpp). Behaviour: doc/jackal_aic_node.md, 'One
 *        publisher per command topic'.
 *
 * While another node publishes on the same command topic (on a stock Jackal: twist_mux still
 * remapped onto jackal_velocity_controller/cmd_vel, or jackal_node's own /cmd_drive) the
 * commands of both reach the wheels interleaved. The node then publishes nothing on that
 * topic (the ControlLoop's state kBlocked) until the other publisher is gone.
 */

#include <cstdint>
#include <string>
#include <vector>

namespace jackal_aic
{
namespace safety
{
/**
 * \brief The conflict state machine of one output topic: clear or conflicted, changed only by
 *        the publisher lists given to update().
 *
 * Transitions, at each update(publishers):
 * - the others are the listed publishers except `self` (duplicates removed, sorted);
 * - clear -> conflicted when there is at least one other (Event::kStarted: log one ERROR
 *   naming them, message());
 * - conflicted -> conflicted with a different set of others (Event::kChanged);
 * - conflicted -> clear when there is none (Event::kEnded: log that driving resumes).
 * queryFailed() (the master did not answer) changes nothing: the last known state is kept,
 * so a master hiccup neither starts nor ends a conflict; it is counted.
 * Not thread-safe: the caller serializes the calls.
 */
class OutputConflict
{
public:
  /// What one update() changed.
  enum class Event
  {
    kNone,     ///< no change
    kStarted,  ///< another publisher appeared: the output is blocked
    kChanged,  ///< still blocked, with a different set of other publishers
    kEnded     ///< the last other publisher left: the output is free again
  };

  /**
   * \param topic  the output topic's resolved name, e.g. "/jackal_velocity_controller/cmd_vel"
   * \param self   this node's name as the master lists it, e.g. "/jackal_AIC"
   * \throws std::invalid_argument if either is empty
   */
  OutputConflict(std::string topic, std::string self);

  /**
   * \brief One poll's answer.
   * \param publishers  node names the master lists as publishers of topic() (this node among
   *                    them or not; any order; empty names are ignored)
   * \param now         the poll's time [s] (any epoch; for since())
   * \return what changed
   */
  Event update(const std::vector<std::string>& publishers, double now);
  /// The master could not be asked (counted; the state is kept).
  void queryFailed() { ++query_failures_; }

  /// True while another node publishes on topic().
  bool conflicted() const { return !others_.empty(); }
  /// The other publishers (sorted, without this node); empty when clear.
  const std::vector<std::string>& others() const { return others_; }
  /// The others as one text, "/a, /b"; "none" when clear.
  std::string othersText() const;
  /// The time [s] the current conflict started (update()'s `now`); NaN when clear.
  double since() const;
  /// The output topic.
  const std::string& topic() const { return topic_; }
  /// This node's name.
  const std::string& self() const { return self_; }
  /// Conflicts started (kStarted events) since construction.
  std::uint64_t conflicts() const { return conflicts_; }
  /// Polls whose master query failed.
  std::uint64_t queryFailures() const { return query_failures_; }
  /**
   * \brief The line to log for an event: kStarted / kChanged (an ERROR) name the other
   *        publishers and say that this node publishes nothing on the topic; kEnded (INFO)
   *        says the output is free again; kNone: empty.
   */
  std::string message(Event event) const;

private:
  std::string topic_;
  std::string self_;
  std::vector<std::string> others_;
  double since_ = 0.0;
  std::uint64_t conflicts_ = 0;
  std::uint64_t query_failures_ = 0;
};

/// "none", "started", "changed", "ended".
const char* toString(OutputConflict::Event event);

}  // namespace safety
}  // namespace jackal_aic
