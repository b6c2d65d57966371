#include <lacerta/base/exceptions.h>

#include <deal.II/base/exceptions.h>

#include <iostream>

namespace lacerta
{
  Error::Error(const std::string &message)
      : std::runtime_error(message)
  {
  }


  int
  run_reporting_errors(const std::function<int()> &body)
  {
    try
    {
      return body();
    }
    catch (const Error &e)
    {
      std::cout.flush();
      std::cerr << "\nError: " << e.what() << std::endl;
    }
    catch (const dealii::ExceptionBase &e)
    {
      std::cout.flush();
      std::cerr << "\nError: ";
      e.print_info(std::cerr);
      std::cerr << std::endl;
    }
    catch (const std::exception &e)
    {
      std::cout.flush();
      std::cerr << "\nError: " << e.what() << std::endl;
    }
    return 1;
  }
} // namespace lacerta
