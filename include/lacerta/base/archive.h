/**
 * @file
 * The binary archive a checkpoint is written to and read from: one serialize() per
 * class describes its state for both directions.
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace lacerta
{
  class Archive;

  /// Whether T has a member `void serialize(Archive &)`.
  template <class T, class = void>
  struct has_serialize : std::false_type
  {
  };
  template <class T>
  struct has_serialize<
    T,
    std::void_t<decltype(std::declval<T &>().serialize(std::declval<Archive &>()))>>
      : std::true_type
  {
  };

  /// Whether T is stored as its bytes: trivially copyable and without serialize().
  template <class T>
  inline constexpr bool stored_as_bytes =
    std::is_trivially_copyable_v<T> && !has_serialize<T>::value;

  /**
   * A binary archive that either appends a state to a string (saving) or reads it back
   * (loading), in the same order. A class describes its state once, in a member
   * `void serialize(Archive &archive)` that passes every member to `archive & member`
   * (or `archive(a, b, c)`), and that one function both saves and loads it, so the
   * two directions cannot disagree. Numbers are stored as their bytes (a checkpoint is
   * read back on the machine that wrote it); containers as their size and elements.
   *
   * Loading checks what it reads: a size larger than what is left, a section tag that
   * is not the expected one, or bytes left over are an Error that names the file.
   */
  class Archive
  {
  public:
    /// An archive that appends what is serialized to @p output.
    explicit Archive(std::string &output);

    /// An archive that reads @p input, the contents of the file @p file_name.
    Archive(const std::string &input, std::string file_name);

    /// Whether the archive reads (the members are set) rather than writes.
    bool
    loading() const
    {
      return input != nullptr;
    }

    /// Writes or reads @p n raw bytes at @p data.
    void
    bytes(void *data, std::size_t n);

    /**
     * Writes the tag @p name, or reads a tag and checks that it is @p name: marks the
     * start of a part of the state, so that a checkpoint that does not match the scene
     * it is read into is refused with the part named, not misread.
     */
    void
    section(const std::string &name);

    /**
     * When loading, checks a size @p n just read against what is left of the input
     * for elements of @p element_bytes each (an Error if it cannot be); returns @p n.
     */
    std::size_t
    size(std::size_t n, std::size_t element_bytes);

    /// After loading: an Error if bytes are left unread.
    void
    finish() const;

    /// Serializes @p value.
    template <class T>
    Archive &
    operator&(T &value);

    /// Serializes every one of @p values in turn.
    template <class... T>
    void
    operator()(T &...values)
    {
      (operator&(values), ...);
    }

    /// The file's name, for messages.
    const std::string &
    file_name() const
    {
      return name;
    }

  private:
    std::string       *output = nullptr;
    const std::string *input  = nullptr;
    std::size_t        offset = 0;
    std::string        name;
  };


  namespace internal
  {
    template <class T>
    void
    serialize_value(Archive &archive, T &value);

    template <class T>
    void
    serialize_vector(Archive &archive, std::vector<T> &v)
    {
      std::size_t n = v.size();
      archive.bytes(&n, sizeof(n));
      if (archive.loading())
      {
        n = archive.size(n, stored_as_bytes<T> ? sizeof(T) : 1);
        v.clear();
        v.resize(n);
      }
      if constexpr (stored_as_bytes<T>)
        archive.bytes(v.data(), n * sizeof(T));
      else
        for (T &x : v)
          serialize_value(archive, x);
    }

    template <class Map>
    void
    serialize_map(Archive &archive, Map &map)
    {
      std::size_t n = map.size();
      archive.bytes(&n, sizeof(n));
      if (archive.loading())
      {
        n = archive.size(n, 1);
        map.clear();
        for (std::size_t i = 0; i < n; ++i)
        {
          typename Map::key_type    key{};
          typename Map::mapped_type value{};
          serialize_value(archive, key);
          serialize_value(archive, value);
          map.emplace(std::move(key), std::move(value));
        }
      }
      else
        for (auto &[key, value] : map)
        {
          auto key_copy = key;
          serialize_value(archive, key_copy);
          serialize_value(archive, value);
        }
    }

    /// Whether T is an instance of the class template Template.
    template <class T, template <class...> class Template>
    struct is_instance : std::false_type
    {
    };
    template <template <class...> class Template, class... Arguments>
    struct is_instance<Template<Arguments...>, Template> : std::true_type
    {
    };
    template <class T>
    struct is_array : std::false_type
    {
    };
    template <class T, std::size_t N>
    struct is_array<std::array<T, N>> : std::true_type
    {
    };

    /// Whether a pointer of the archive matches one of the state: both or neither.
    void
    check_presence(Archive &archive, bool present);

    template <class T>
    void
    serialize_value(Archive &archive, T &value)
    {
      if constexpr (has_serialize<T>::value)
        value.serialize(archive);
      else if constexpr (stored_as_bytes<T>)
        archive.bytes(&value, sizeof(T));
      else if constexpr (std::is_same_v<T, std::string>)
      {
        std::size_t n = value.size();
        archive.bytes(&n, sizeof(n));
        if (archive.loading())
          value.resize(archive.size(n, 1));
        archive.bytes(value.data(), value.size());
      }
      else if constexpr (is_instance<T, std::vector>::value)
        serialize_vector(archive, value);
      else if constexpr ((is_instance<T, std::map>::value
                          || is_instance<T, std::unordered_map>::value))
        serialize_map(archive, value);
      else if constexpr (is_array<T>::value)
      {
        for (auto &x : value)
          serialize_value(archive, x);
      }
      else if constexpr (is_instance<T, std::pair>::value)
      {
        serialize_value(archive, value.first);
        serialize_value(archive, value.second);
      }
      else if constexpr (is_instance<T, std::optional>::value)
      {
        bool present = value.has_value();
        archive.bytes(&present, sizeof(present));
        if (archive.loading())
        {
          if (present)
            value.emplace();
          else
            value.reset();
        }
        if (present)
          serialize_value(archive, *value);
      }
      else if constexpr (is_instance<T, std::unique_ptr>::value)
      {
        // The object exists already (the scene was built from the same parameters):
        // only its state is read into it.
        check_presence(archive, value != nullptr);
        if (value)
          serialize_value(archive, *value);
      }
      else
        static_assert(sizeof(T) == 0, "no serialization for this type");
    }
  } // namespace internal


  template <class T>
  Archive &
  Archive::operator&(T &value)
  {
    internal::serialize_value(*this, value);
    return *this;
  }
} // namespace lacerta
