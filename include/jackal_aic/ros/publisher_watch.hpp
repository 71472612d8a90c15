#pragma once
/**
 * \file publisher_watch.hpp
 * \brief The publishers of one topic, polled from the ROS master (getSystemState) on a thread
 *        of its own, for the node's OutputConflict (include/jackal_aic/safety/output_conflict.hpp;
 *        doc/jackal_aic_node.md, 'One publisher per command topic').
 */

#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace jackal_aic
{
namespace node
{
/**
 * \brief Asks the master every `period` (wall time) which nodes publish on a topic and hands
 *        the answer to a callback, on its own thread, so a slow master never delays the
 *        control loop. A publisher the master lists is one whether or not it has sent a
 *        message (a subscriber's count on this node's publisher would not see it).
 */
class PublisherWatch
{
public:
  /**
   * \brief One poll's answer.
   * \param ok          false if the master could not be asked (`publishers` is then empty)
   * \param publishers  node names publishing on the topic, this node among them (ok only)
   * \param error       why the query failed (!ok only)
   */
  using Callback = std::function<void(bool ok, const std::vector<std::string>& publishers, const std::string& error)>;

  /**
   * \brief Node names the master lists as publishers of `topic` (XML-RPC getSystemState).
   * \param topic   resolved topic name, e.g. "/cmd_drive"
   * \param out     the names (empty: no publisher); unchanged on failure
   * \param error   why it failed (optional)
   * \return false if the master did not answer or the answer is malformed
   */
  static bool publishersOf(const std::string& topic, std::vector<std::string>* out, std::string* error = nullptr);
  /// As publishersOf(), for the nodes the master lists as subscribers of `topic`.
  static bool subscribersOf(const std::string& topic, std::vector<std::string>* out, std::string* error = nullptr);

  /**
   * \brief Start polling: the first poll at once (on the thread), then every `period`.
   * \param topic     resolved topic name
   * \param period    [s] wall time between polls, > 0
   * \param callback  called on the watch's thread after every poll; must be thread-safe
   * \throws std::invalid_argument if period <= 0 or the topic is empty
   */
  PublisherWatch(std::string topic, double period, Callback callback);
  /// Stops and joins the thread (a poll in progress ends first).
  ~PublisherWatch();
  PublisherWatch(const PublisherWatch&) = delete;
  PublisherWatch& operator=(const PublisherWatch&) = delete;

private:
  /// publishersOf() (kind 0) or subscribersOf() (kind 1): getSystemState's list of that kind.
  static bool registeredNodes(const std::string& topic, int kind, std::vector<std::string>* out, std::string* error);
  void run();

  std::string topic_;
  double period_;
  Callback callback_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace node
}  // namespace jackal_aic
