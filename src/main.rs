fn main() {
    println!("deadreckon");
}
