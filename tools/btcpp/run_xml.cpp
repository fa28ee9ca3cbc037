// Loads a BehaviorTree.CPP v4 XML file and ticks it with tickExactlyOnce until it is not
// RUNNING (at most 50 ticks): prints each tick's status, then the root blackboard's entries
// ("?" for an entry without a string or number value).
//
// It wrote tests/engine/data/btcpp/builtins_run_by_btcpp.txt. Built against BehaviorTree.CPP
// 4.10.0 from source (cmake -DBTCPP_SHARED_LIBS=OFF -DBUILD_TESTING=OFF
// -DBTCPP_EXAMPLES=OFF -DBTCPP_BUILD_TOOLS=OFF -DBTCPP_GROOT_INTERFACE=OFF
// -DBTCPP_SQLITE_LOGGING=OFF), then:
//   g++ -std=c++17 -I SRC/include run_xml.cpp -o run_xml BUILD/libbehaviortree_cpp.a
//       BUILD/3rdparty/tinyxml2/libtinyxml2.a BUILD/3rdparty/minitrace/libminitrace.a
//       -lpthread -ldl
#include <behaviortree_cpp/bt_factory.h>
#include <iostream>
#include <fstream>
#include <sstream>

int main(int argc, char** argv)
{
  if(argc < 2) { std::cerr << "usage: run_xml FILE\n"; return 2; }
  std::ifstream in(argv[1]);
  std::stringstream text;
  text << in.rdbuf();
  BT::BehaviorTreeFactory factory;
  try
  {
    auto tree = factory.createTreeFromText(text.str());
    BT::NodeStatus status = BT::NodeStatus::RUNNING;
    for(int i = 0; i < 50 && status == BT::NodeStatus::RUNNING; i++)
    {
      status = tree.tickExactlyOnce();
      std::cout << BT::toStr(status) << "\n";
    }
    auto bb = tree.rootBlackboard();
    for(auto key : bb->getKeys())
    {
      auto entry = bb->getEntry(std::string(key));
      if(!entry) continue;
      std::cout << "bb " << key << " = ";
      if(entry->value.isString()) std::cout << "'" << entry->value.cast<std::string>() << "'";
      else if(entry->value.isIntegral()) std::cout << entry->value.cast<int64_t>();
      else if(entry->value.isNumber()) std::cout << entry->value.cast<double>();
      else std::cout << "?";
      std::cout << "\n";
    }
  }
  catch(const std::exception& e)
  {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
