"""Tools around BehaviorTree.CPP: its checker program and the random trees compared with it."""
