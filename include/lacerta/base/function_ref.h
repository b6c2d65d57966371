/**
 * @file
 * A non-owning reference to a callable, for callbacks on hot paths.
 */
#pragma once

#include <memory>
#include <type_traits>
#include <utility>

namespace lacerta
{
  template <typename Signature>
  class FunctionRef;

  /**
   * A reference to a callable with the signature `Result(Arguments...)`, passed by
   * value to a function that calls it before returning: unlike std::function it
   * neither allocates nor copies the callable, so a lambda that captures by reference
   * costs nothing to pass on every time step. The callable must outlive the call that
   * receives the reference.
   */
  template <typename Result, typename... Arguments>
  class FunctionRef<Result(Arguments...)>
  {
  public:
    /// Refers to @p callable (not copied: it must outlive this reference's use).
    template <
      typename Callable,
      typename = std::enable_if_t<!std::is_same_v<std::decay_t<Callable>, FunctionRef>>>
    FunctionRef(Callable &&callable)
        : object(const_cast<void *>(static_cast<const void *>(std::addressof(callable))))
        , call(
            [](void *object, Arguments... arguments) -> Result
            {
              return (*static_cast<std::remove_reference_t<Callable> *>(object))(
                std::forward<Arguments>(arguments)...);
            })
    {
    }

    /// Calls the callable referred to.
    Result
    operator()(Arguments... arguments) const
    {
      return call(object, std::forward<Arguments>(arguments)...);
    }

  private:
    /// The callable.
    void *object;

    /// Calls the callable at its address with the arguments.
    Result (*call)(void *, Arguments...);
  };
} // namespace lacerta
