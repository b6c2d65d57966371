/**
 * @file
 * A signal: a list of subscribers called in turn, after ASPECT's SimulatorSignals
 * (boost::signals2 there; the project needs no more than this).
 */
#pragma once

#include <functional>
#include <utility>
#include <vector>

namespace lacerta
{
  /**
   * Subscribers to one event, called in the order they connected, with the event's
   * arguments. A subscriber stays connected for the signal's lifetime: whoever connects
   * must outlive the signal's owner or not connect.
   */
  template <typename... Args>
  class Signal
  {
  public:
    /// Adds @p subscriber to the end of the list.
    void
    connect(std::function<void(Args...)> subscriber)
    {
      subscribers.push_back(std::move(subscriber));
    }

    /// Calls every subscriber with @p args.
    void
    operator()(const Args &...args) const
    {
      for (const auto &subscriber : subscribers)
        subscriber(args...);
    }

  private:
    std::vector<std::function<void(Args...)>> subscribers;
  };
} // namespace lacerta
