// The checker program of tests/engine/test_btcpp_real.py: BehaviorTree.CPP's own factory
// loading our exports.
//
//   check_load MODELS.txt load TREE.xml   registers every model of MODELS.txt (lines
//                                         "node ELEMENT ID", "port in|out NAME TYPE",
//                                         "default TEXT", "doc TEXT"; TYPE is double, bool or
//                                         std::string) as a node that succeeds, loads the
//                                         XML with createTreeFromText and prints
//                                         WriteTreeToXML; exit 0, or the library's error on
//                                         stderr and exit 1.
//   check_load MODELS.txt models          prints writeTreeNodesModelXML(factory).
//
// Built against BehaviorTree.CPP 4.10.0 from source as tools/btcpp/run_xml.cpp is:
//   g++ -std=c++17 -I SRC/include check_load.cpp -o check_load BUILD/libbehaviortree_cpp.a
//       BUILD/3rdparty/tinyxml2/libtinyxml2.a BUILD/3rdparty/minitrace/libminitrace.a
//       -lpthread -ldl
#include <behaviortree_cpp/bt_factory.h>
#include <behaviortree_cpp/xml_parsing.h>
#include <fstream>
#include <iostream>
#include <sstream>

namespace
{
struct Model
{
  std::string element;
  std::string id;
  BT::PortsList ports;
  std::string last_port;
};

class Action : public BT::SyncActionNode
{
public:
  Action(const std::string& name, const BT::NodeConfig& config) : SyncActionNode(name, config) {}
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

class Condition : public BT::ConditionNode
{
public:
  Condition(const std::string& name, const BT::NodeConfig& config) : ConditionNode(name, config) {}
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

class Control : public BT::ControlNode
{
public:
  Control(const std::string& name, const BT::NodeConfig& config) : ControlNode(name, config) {}
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

class Decorator : public BT::DecoratorNode
{
public:
  Decorator(const std::string& name, const BT::NodeConfig& config) : DecoratorNode(name, config) {}
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

std::pair<std::string, BT::PortInfo> make_port(const std::string& direction,
                                               const std::string& name, const std::string& type)
{
  bool in = direction == "in";
  if(type == "double")
    return in ? BT::InputPort<double>(name) : BT::OutputPort<double>(name);
  if(type == "bool")
    return in ? BT::InputPort<bool>(name) : BT::OutputPort<bool>(name);
  return in ? BT::InputPort<std::string>(name) : BT::OutputPort<std::string>(name);
}

std::vector<Model> read_models(const std::string& path)
{
  std::ifstream in(path);
  if(!in)
    throw std::runtime_error("cannot read " + path);
  std::vector<Model> models;
  std::string line;
  while(std::getline(in, line))
  {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if(word == "node")
    {
      Model model;
      words >> model.element >> model.id;
      models.push_back(model);
    }
    else if(word == "port" && !models.empty())
    {
      std::string direction, name, type;
      words >> direction >> name >> type;
      models.back().ports.insert(make_port(direction, name, type));
      models.back().last_port = name;
    }
    else if((word == "default" || word == "doc") && !models.empty() &&
            !models.back().last_port.empty())
    {
      std::string rest;
      std::getline(words, rest);
      if(!rest.empty() && rest[0] == ' ')
        rest.erase(0, 1);
      auto& info = models.back().ports.at(models.back().last_port);
      if(word == "default")
        info.setDefaultValue(rest);
      else
        info.setDescription(rest);
    }
  }
  return models;
}

template <typename T>
void add(BT::BehaviorTreeFactory& factory, const Model& model, BT::NodeType type)
{
  BT::TreeNodeManifest manifest{ type, model.id, model.ports, {} };
  factory.registerBuilder(manifest, [](const std::string& name, const BT::NodeConfig& config) {
    return std::make_unique<T>(name, config);
  });
}

void register_models(BT::BehaviorTreeFactory& factory, const std::vector<Model>& models)
{
  for(const auto& model : models)
  {
    if(model.element == "Condition")
      add<Condition>(factory, model, BT::NodeType::CONDITION);
    else if(model.element == "Control")
      add<Control>(factory, model, BT::NodeType::CONTROL);
    else if(model.element == "Decorator")
      add<Decorator>(factory, model, BT::NodeType::DECORATOR);
    else
      add<Action>(factory, model, BT::NodeType::ACTION);
  }
}
}  // namespace

int main(int argc, char** argv)
{
  if(argc < 3)
  {
    std::cerr << "usage: check_load MODELS.txt load TREE.xml | check_load MODELS.txt models\n";
    return 2;
  }
  try
  {
    BT::BehaviorTreeFactory factory;
    register_models(factory, read_models(argv[1]));
    std::string command = argv[2];
    if(command == "models")
    {
      std::cout << BT::writeTreeNodesModelXML(factory) << "\n";
      return 0;
    }
    if(command == "load" && argc >= 4)
    {
      std::ifstream in(argv[3]);
      std::stringstream text;
      text << in.rdbuf();
      auto tree = factory.createTreeFromText(text.str());
      std::cout << BT::WriteTreeToXML(tree, true, false) << "\n";
      return 0;
    }
    std::cerr << "unknown command " << command << "\n";
    return 2;
  }
  catch(const std::exception& error)
  {
    std::cerr << error.what() << "\n";
    return 1;
  }
}
